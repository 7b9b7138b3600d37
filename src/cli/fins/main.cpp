// fins: read, write and probe an Omron PLC (or finsd) over FINS/UDP or FINS/TCP.
//
// Exit codes: 0 success; 2 usage error (bad option, address or value, a range past the
// area's end, a value that does not decode as asked); 3 transport failure (cannot
// connect, timeout, connection lost, malformed answer); 4 the PLC answered with a
// non-zero end code (printed as hex and name).
#include <cstdio>
#include <string>
#include <string_view>
#include <vector>

#include <fmt/core.h>
#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include "cli/fins/commands.hpp"

namespace fins::cli {
// verbs_modbus.cpp (28 04 / 28 05), verbs_watch.cpp (01 04 polling), verbs_discover.cpp
// (05 01 over an IPv4 range).
void add_modbus_verbs(CLI::App& app, const GlobalOptions& g, int& exit_code);
void add_watch_verbs(CLI::App& app, const GlobalOptions& g, int& exit_code);
void add_discover_verbs(CLI::App& app, const GlobalOptions& g, int& exit_code);
}  // namespace fins::cli

int main(int argc, char** argv) {
    using namespace fins::cli;
    CLI::App app{"fins: talk FINS to an Omron CS/CJ/CP/NX PLC or to finsd"};
    // Options are --name on Windows too. CLI11 also takes /name there by default, and then
    // a PLC path (`fins files put a.bin /DIR/A.BIN`) was taken for an option; the
    // verbs made after this inherit it.
    app.allow_windows_style_options(false);
    app.require_subcommand(1);
    // Global options may also follow the verb: `fins read D100 --json`.
    app.fallthrough(true);
    app.set_version_flag("--version", std::string("fins ") + FINSKIT_VERSION);
    // Errors found before --json is parsed still honour it.
    const auto json_asked = [argc, argv] {
        bool json = false;
        for (int i = 1; i < argc; ++i)
            json = json || std::string_view(argv[i]) == "--json";
        return json;
    };
    GlobalOptions g;
    if (const auto bad = apply_environment(g, argc, argv)) return Output{json_asked()}.usage(*bad);
    add_global_options(app, g);

    std::string as = "uint16";
    auto add_as = [&as](CLI::App* c) {
        c->add_option("--as", as,
                      "Value format: int16 uint16 int32 uint32 float double bcd string bits hex")
            ->capture_default_str();
    };

    ReadArgs read;
    auto* c_read = app.add_subcommand("read", "Read consecutive values (01 01)");
    c_read->add_option("address", read.address, "Start address, e.g. D100, CIO10.13, E3_0, T5")
        ->required();
    c_read->add_option("count", read.count, "Number of values (string: words)")
        ->capture_default_str()
        ->check(CLI::Range(1, 65535));
    add_as(c_read);

    WriteArgs write;
    auto* c_write = app.add_subcommand("write", "Write consecutive values (01 02)");
    c_write->add_option("address", write.address, "Start address")->required();
    c_write->add_option("values", write.values, "Values to write")->required();
    add_as(c_write);

    FillArgs fill;
    auto* c_fill = app.add_subcommand("fill", "Write one word to a range of words (01 03)");
    c_fill->add_option("address", fill.address, "Start word address")->required();
    c_fill->add_option("count", fill.count, "Number of words")->required();
    c_fill->add_option("value", fill.value, "Word value (decimal or 0x hex)")->required();

    TransferArgs transfer;
    auto* c_transfer = app.add_subcommand("transfer", "Copy words inside the PLC (01 05)");
    c_transfer->add_option("from", transfer.from, "Source word address")->required();
    c_transfer->add_option("to", transfer.to, "Destination word address")->required();
    c_transfer->add_option("count", transfer.count, "Number of words")->required();

    ReadMultiArgs multi;
    auto* c_multi =
        app.add_subcommand("read-multi", "Read scattered addresses in one request (01 04)");
    c_multi->add_option("addresses", multi.addresses, "Addresses")->required();

    RawArgs raw;
    auto* c_raw = app.add_subcommand(
        "raw", "Send any command in hex and print the decoded answer (like W596 SendCmd)");
    c_raw->add_option("command", raw.command, "Command code MRC SRC in hex, e.g. 0101")->required();
    c_raw->add_option("parameters", raw.parameters, "Parameter bytes in hex (spaces allowed)");
    c_raw->add_flag("--no-response", raw.no_response,
                    "Set the ICF no-response bit and do not wait");

    app.add_subcommand("probe",
                       "Show which FINS node answers at --host/--port (and the --dest to use)");

    int group_rc = -1;
    add_plc_data_verbs(app, g, group_rc);
    add_control_verbs(app, g, group_rc);
    add_diagnostic_verbs(app, g, group_rc);
    add_file_verbs(app, g, group_rc);
    add_watch_verbs(app, g, group_rc);
    add_discover_verbs(app, g, group_rc);
    add_modbus_verbs(app, g, group_rc);

    describe_global_options(app);

    try {
        app.parse(argc, argv);
    } catch (const CLI::ParseError& e) {
        // --help and --version print and exit 0; every other parse error is a usage
        // error like any other, with the prefix and, under --json, as JSON.
        if (e.get_exit_code() == 0) return app.exit(e);
        Output out{json_asked()};
        if (const auto verb = explain_missing_verb(app)) return out.usage(*verb);
        return out.usage(fmt::format("{} (see fins --help)", e.what()));
    }
    if (group_rc >= 0) return group_rc;
    Output out{g.json};
    if (c_raw->parsed()) return run_raw(g, raw, out);
    if (app.got_subcommand("probe")) return run_probe(g, out);
    auto format = parse_format(as);
    if (!format) return out.usage(fmt::format("unknown --as format '{}'", as));
    if (c_read->parsed()) return run_read(g, read, *format, out);
    if (c_write->parsed()) return run_write(g, write, *format, out);
    if (c_fill->parsed()) return run_fill(g, fill, out);
    if (c_transfer->parsed()) return run_transfer(g, transfer, out);
    if (c_multi->parsed()) return run_read_multi(g, multi, out);
    return exit_usage;
}
