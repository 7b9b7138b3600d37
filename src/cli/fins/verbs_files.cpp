// `fins files` verbs for 22 xx file memory (docs/file-memory.md):
//   files ls [DIR]                      22 01 over as many requests as needed
//   files get PLCFILE [LOCAL|-]         22 02 in pipelined chunks (LOCAL default: the name)
//   files put LOCAL PLCFILE [--force]   22 03: create (0000), --force replaces (0001)
//   files rm PLCFILE...                 22 05, one request per directory
//   files cp FROM TO                    22 07 (between devices too)
//   files mv PLCFILE NEWNAME            22 08 (files and directories)
//   files mkdir DIR / rmdir DIR         22 15
//   files format card|em --yes          22 04
//   files save WHAT PLCFILE [COUNT]     22 0A/0B/0C area -> file (or WHAT COUNT PLCFILE)
//   files load PLCFILE WHAT [COUNT]     file -> area
//   files compare PLCFILE WHAT [COUNT]  compare (exit 4 with 2007 on a difference, saying
//                                       where: verbs_files_transfer.cpp)
//   files cassette save|load|verify|init|type   22 20 (verbs_cassette.cpp)
// PLC paths: [card:|em:][/]DIR/.../NAME.EXT ("\" works too); card is the default.
// WHAT: a word address (D100, E3_0, W10 ...), a parameter area (plc-setup, io-table,
// routing, cpu-bus) or "program". Exit codes as every verb: 0, 2, 3, 4.
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <fstream>
#include <iterator>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <fmt/core.h>

#include "cli/fins/commands.hpp"
#include "cli/fins/verbs_files_transfer.hpp"
#include "fins/commands/file_memory.hpp"
#include "fins/commands/parameter_area.hpp"

namespace fins::cli {

void add_cassette_verbs(CLI::App& files, const GlobalOptions& g, int& exit_code);  // 22 20

namespace {

struct PlcPath {
    std::uint16_t disk = disk_memory_card;
    std::string directory;  // "" or "\A\B"
    std::string name;       // last component ("" for a bare device)
};

std::optional<PlcPath> parse_plc_path(std::string text) {
    PlcPath p;
    if (text.starts_with("card:")) {
        text.erase(0, 5);
    } else if (text.starts_with("em:")) {
        p.disk = disk_em_file;
        text.erase(0, 3);
    }
    std::vector<std::string> parts;
    std::string current;
    for (const char c : text) {
        if (c == '/' || c == '\\') {
            if (!current.empty()) parts.push_back(current);
            current.clear();
        } else {
            current.push_back(c);
        }
    }
    if (!current.empty()) parts.push_back(current);
    if (!parts.empty()) {
        p.name = parts.back();
        parts.pop_back();
    }
    for (const auto& d : parts)
        p.directory += "\\" + d;
    return p;
}

// The directory itself as a path ("\A\B"), for ls/mkdir/rmdir arguments.
std::string as_directory(const PlcPath& p) {
    return p.name.empty() ? p.directory : p.directory + "\\" + p.name;
}

std::string date_text(std::uint32_t d) {
    return fmt::format("{:04}-{:02}-{:02} {:02}:{:02}:{:02}", 1980 + (d >> 25), (d >> 21) & 0x0F,
                       (d >> 16) & 0x1F, (d >> 11) & 0x1F, (d >> 5) & 0x3F, (d & 0x1F) * 2);
}

// A progress bar on stderr when it is a terminal, after half a second.
class Progress {
  public:
    explicit Progress(bool enabled) : enabled_(enabled && ::isatty(STDERR_FILENO) == 1) {}
    ~Progress() {
        if (shown_) std::fputs("\n", stderr);
    }
    void operator()(std::uint64_t done, std::uint64_t total) {
        if (!enabled_ || std::chrono::steady_clock::now() - start_ < std::chrono::milliseconds(500))
            return;
        shown_ = true;
        const auto pct = total == 0 ? 100 : static_cast<unsigned>(done * 100 / total);
        const std::string bar(pct / 4, '#');
        std::fprintf(stderr, "\r[%-25s] %3u%% %llu/%llu bytes", bar.c_str(), pct,
                     static_cast<unsigned long long>(done), static_cast<unsigned long long>(total));
    }

  private:
    bool enabled_;
    bool shown_ = false;
    std::chrono::steady_clock::time_point start_ = std::chrono::steady_clock::now();
};

struct FileArgs {
    std::vector<std::string> paths;  // PLC paths; single-path verbs use paths[0]
    std::string plc;
    std::string local;
    std::string what;
    unsigned count = 0;
    bool force = false;
    bool yes = false;
};

std::optional<FileName> name_of(const std::string& text) {
    return FileName::from(text);
}

int bad_name(Output& out, const std::string& text) {
    return out.usage(fmt::format("'{}' is not an 8.3 file name", text));
}

int run_ls(const GlobalOptions& g, const FileArgs& a, Output& out) {
    const auto p = parse_plc_path(a.paths.empty() ? "" : a.paths[0]);
    int rc = exit_ok;
    auto client = open_client(g, out, rc);
    if (!client) return rc;
    const auto r = list_directory(*client, p->disk, as_directory(*p));
    if (!r) return out.failure(r.error(), "files ls");
    nlohmann::json files = nlohmann::json::array();
    std::string text =
        fmt::format("{} {}  {} of {} bytes free\n", r->disk.volume_label.text(),
                    date_text(r->disk.date), r->disk.free_capacity, r->disk.total_capacity);
    for (const auto& f : r->files) {
        // The root's volume label entry (5-3-32, attribute 08) is the header line above.
        if ((f.attribute & attribute_volume) != 0) continue;
        const bool dir = (f.attribute & attribute_directory) != 0;
        files.push_back({{"name", f.name.text()},
                         {"size", f.size},
                         {"date", date_text(f.date)},
                         {"directory", dir},
                         {"attribute", f.attribute}});
        text += fmt::format("{:<12} {:>10} {}\n", f.name.text() + (dir ? "\\" : ""),
                            dir ? std::string("<DIR>") : std::to_string(f.size), date_text(f.date));
    }
    out.print({{"volume", r->disk.volume_label.text()},
               {"total_bytes", r->disk.total_capacity},
               {"free_bytes", r->disk.free_capacity},
               {"files", files}},
              text);
    return exit_ok;
}

int run_get(const GlobalOptions& g, const FileArgs& a, Output& out) {
    const auto p = parse_plc_path(a.paths[0]);
    const auto name = name_of(p->name);
    if (!name) return bad_name(out, p->name);
    const std::string local = a.local.empty() ? p->name : a.local;
    int rc = exit_ok;
    auto client = open_client(g, out, rc);
    if (!client) return rc;
    Progress progress(!g.json && local != "-");
    const auto data = get_file(*client, p->disk, p->directory, *name,
                               [&](std::uint64_t d, std::uint64_t t) { progress(d, t); });
    if (!data) return out.failure(data.error(), "files get");
    if (local == "-") {
        std::fwrite(data->data(), 1, data->size(), stdout);
        return exit_ok;
    }
    std::ofstream f(local, std::ios::binary | std::ios::trunc);
    f.write(reinterpret_cast<const char*>(data->data()),
            static_cast<std::streamsize>(data->size()));
    if (!f) return out.usage(fmt::format("cannot write '{}'", local));
    out.print({{"file", p->name}, {"bytes", data->size()}, {"local", local}},
              fmt::format("got {} ({} bytes) into {}\n", p->name, data->size(), local));
    return exit_ok;
}

int run_put(const GlobalOptions& g, const FileArgs& a, Output& out) {
    const auto p = parse_plc_path(a.paths[0]);
    const auto name = name_of(p->name);
    if (!name) return bad_name(out, p->name);
    std::ifstream f(a.local, std::ios::binary);
    if (!f) return out.usage(fmt::format("cannot read '{}'", a.local));
    const std::vector<std::uint8_t> data((std::istreambuf_iterator<char>(f)), {});
    if (data.size() > 0xFFFFFFFFu) return out.usage("files are at most 4 GiB (22 03 positions)");
    int rc = exit_ok;
    auto client = open_client(g, out, rc);
    if (!client) return rc;
    Progress progress(!g.json);
    const auto r = put_file(*client, p->disk, p->directory, *name, data, a.force,
                            [&](std::uint64_t d, std::uint64_t t) { progress(d, t); });
    if (!r) return out.failure(r.error(), "files put");
    out.print({{"file", p->name}, {"bytes", data.size()}},
              fmt::format("put {} ({} bytes)\n", p->name, data.size()));
    return exit_ok;
}

int run_rm(const GlobalOptions& g, const FileArgs& a, Output& out) {
    std::map<std::pair<std::uint16_t, std::string>, std::vector<FileName>> groups;
    for (const auto& text : a.paths) {
        const auto p = parse_plc_path(text);
        const auto name = name_of(p->name);
        if (!name) return bad_name(out, p->name);
        groups[{p->disk, p->directory}].push_back(*name);
    }
    int rc = exit_ok;
    auto client = open_client(g, out, rc);
    if (!client) return rc;
    unsigned deleted = 0;
    for (const auto& [where, names] : groups) {
        const auto r = client->send(FileDelete{where.first, names, where.second});
        if (!r) return out.failure(r.error(), "files rm");
        deleted += r->deleted;
    }
    out.print({{"deleted", deleted}}, fmt::format("deleted {} file(s)\n", deleted));
    return exit_ok;
}

template <class C>
int simple(const GlobalOptions& g, Output& out, const C& command, const std::string& what) {
    int rc = exit_ok;
    auto client = open_client(g, out, rc);
    if (!client) return rc;
    if (const auto r = client->send(command); !r) return out.failure(r.error(), what);
    out.print({{"ok", true}}, what + ": done\n");
    return exit_ok;
}

int run_cp(const GlobalOptions& g, const FileArgs& a, Output& out) {
    const auto from = parse_plc_path(a.paths[0]);
    const auto to = parse_plc_path(a.paths[1]);
    const auto n1 = name_of(from->name);
    const auto n2 = name_of(to->name);
    if (!n1 || !n2) return bad_name(out, !n1 ? from->name : to->name);
    return simple(g, out, FileCopy{from->disk, *n1, to->disk, *n2, from->directory, to->directory},
                  "files cp");
}

int run_mv(const GlobalOptions& g, const FileArgs& a, Output& out) {
    const auto from = parse_plc_path(a.paths[0]);
    const auto n1 = name_of(from->name);
    const auto n2 = name_of(a.paths[1]);
    if (!n1 || !n2) return bad_name(out, !n1 ? from->name : a.paths[1]);
    return simple(g, out, FileNameChange{from->disk, *n1, *n2, from->directory}, "files mv");
}

int directory_verb(const GlobalOptions& g, const FileArgs& a, Output& out, DirectoryOperation op) {
    const auto p = parse_plc_path(a.paths[0]);
    const auto name = name_of(p->name);
    if (!name) return bad_name(out, p->name);
    return simple(
        g, out, DirectoryCreateDelete{p->disk, static_cast<std::uint16_t>(op), *name, p->directory},
        op == DirectoryOperation::create ? "files mkdir" : "files rmdir");
}

int run_mkdir(const GlobalOptions& g, const FileArgs& a, Output& out) {
    return directory_verb(g, a, out, DirectoryOperation::create);
}
int run_rmdir(const GlobalOptions& g, const FileArgs& a, Output& out) {
    return directory_verb(g, a, out, DirectoryOperation::remove);
}

int run_format(const GlobalOptions& g, const FileArgs& a, Output& out) {
    if (a.paths[0] != "card" && a.paths[0] != "em") return out.usage("format: card or em");
    if (!a.yes) return out.usage("format erases every file: add --yes");
    return simple(g, out, FileMemoryFormat{a.paths[0] == "em" ? disk_em_file : disk_memory_card},
                  "files format");
}

// save / load / compare: 22 0A (address), 22 0B (parameter area), 22 0C (program).
int transfer(const GlobalOptions& g, const FileArgs& args, Output& out, FileTransferMode mode) {
    const auto a = transfer_arguments(mode, args.paths);
    if (!a.problem.empty()) return out.usage(a.problem);
    const auto p = parse_plc_path(a.plc);
    const auto name = name_of(p->name);
    if (!name) return bad_name(out, p->name);
    const auto code = static_cast<std::uint16_t>(mode);
    const char* verb = mode == FileTransferMode::to_file
                           ? "files save"
                           : (mode == FileTransferMode::from_file ? "files load" : "files compare");
    int rc = exit_ok;
    std::unique_ptr<Client> client;
    auto done = [&](std::uint64_t n, const char* unit) {
        out.print({{"count", n}, {"unit", unit}}, fmt::format("{}: {} {}\n", verb, n, unit));
        return exit_ok;
    };
    // A compare that found a difference (2007) says where, both values and how many.
    auto failed = [&](std::error_code ec, const CompareTarget& target) {
        if (mode != FileTransferMode::compare || ec != make_error_code(EndCode::data_mismatch))
            return out.failure(ec, verb);
        const auto where = describe_file_difference(*client, p->disk, p->directory, *name, target);
        return out.failure(ec,
                           where.empty() ? std::string(verb) : fmt::format("{}: {}", verb, where));
    };
    if (a.what == "program") {
        if (!(client = open_client(g, out, rc))) return rc;
        const auto r = client->send(
            ProgramAreaFileTransfer{code, 0xFFFF, 0, 0xFFFFFFFF, p->disk, *name, p->directory});
        return r ? done(r->length, "bytes")
                 : failed(r.error(), {CompareTarget::Kind::program, {}, 0, nullptr});
    }
    if (const auto* area = find_parameter_area(std::string_view(a.what));
        area != nullptr && area->code != parameter_area_all) {
        if (!(client = open_client(g, out, rc))) return rc;
        const auto r = client->send(ParameterAreaFileTransfer{
            code, area->code, 0, whole_parameter_area, p->disk, *name, p->directory});
        return r ? done(r->count, "words")
                 : failed(r.error(), {CompareTarget::Kind::parameters, {}, 0, area});
    }
    const auto address = parse_address(a.what);
    const Result<MemoryAddress> mem = address ? to_memory_address(*address, Access::word)
                                              : Result<MemoryAddress>(Unexpected(address.error()));
    if (!mem)
        return out.usage(
            fmt::format("'{}' is not a word address, parameter area or program", a.what));
    if (a.count == 0 || a.count > 0xFFFF) return out.usage("COUNT: 1-65535 words");
    if (!(client = open_client(g, out, rc))) return rc;
    const auto r = client->send(MemoryAreaFileTransfer{
        code, *mem, static_cast<std::uint16_t>(a.count), p->disk, *name, p->directory});
    return r ? done(r->count, "words")
             : failed(r.error(), {CompareTarget::Kind::words, *address, a.count, nullptr});
}

int run_save(const GlobalOptions& g, const FileArgs& a, Output& out) {
    return transfer(g, a, out, FileTransferMode::to_file);
}
int run_load(const GlobalOptions& g, const FileArgs& a, Output& out) {
    return transfer(g, a, out, FileTransferMode::from_file);
}
int run_compare(const GlobalOptions& g, const FileArgs& a, Output& out) {
    return transfer(g, a, out, FileTransferMode::compare);
}

CLI::App* verb(CLI::App& parent, const char* name, const char* help, const GlobalOptions& g,
               int& exit_code, const std::shared_ptr<FileArgs>& args,
               int (*run)(const GlobalOptions&, const FileArgs&, Output&)) {
    auto* c = parent.add_subcommand(name, help);
    c->callback([&g, &exit_code, args, run] {
        Output out{g.json};
        if (!args->plc.empty()) args->paths.insert(args->paths.begin(), args->plc);
        exit_code = run(g, *args, out);
    });
    return c;
}

}  // namespace

void add_file_verbs(CLI::App& app, const GlobalOptions& g, int& exit_code) {
    auto* files = app.add_subcommand("files", "Memory card and EM file memory (22 xx)");
    files->require_subcommand(1);
    const char* path_help = "PLC path [card:|em:]/DIR/NAME.EXT";
    auto a = std::make_shared<FileArgs>();
    auto* c = verb(*files, "ls", "List a directory (22 01)", g, exit_code, a, &run_ls);
    c->add_option("dir", a->plc, "PLC directory (default: card root)");

    a = std::make_shared<FileArgs>();
    c = verb(*files, "get", "Copy a PLC file to the host (22 02)", g, exit_code, a, &run_get);
    c->add_option("plcfile", a->plc, path_help)->required();
    c->add_option("local", a->local, "Host file (default: the PLC name; - = stdout)");

    a = std::make_shared<FileArgs>();
    c = verb(*files, "put", "Copy a host file to the PLC (22 03)", g, exit_code, a, &run_put);
    c->add_option("local", a->local, "Host file")->required();
    c->add_option("plcfile", a->plc, path_help)->required();
    c->add_flag("--force,-f", a->force, "Replace an existing file (parameter 0001)");

    a = std::make_shared<FileArgs>();
    c = verb(*files, "rm", "Delete files (22 05)", g, exit_code, a, &run_rm);
    c->add_option("plcfiles", a->paths, path_help)->required();

    a = std::make_shared<FileArgs>();
    c = verb(*files, "cp", "Copy a file, also between devices (22 07)", g, exit_code, a, &run_cp);
    c->add_option("from_to", a->paths, "FROM TO")->required()->expected(2);

    a = std::make_shared<FileArgs>();
    c = verb(*files, "mv", "Rename a file or directory (22 08)", g, exit_code, a, &run_mv);
    c->add_option("from_name", a->paths, "PLCFILE NEWNAME")->required()->expected(2);

    a = std::make_shared<FileArgs>();
    c = verb(*files, "mkdir", "Create a directory (22 15)", g, exit_code, a, &run_mkdir);
    c->add_option("dir", a->plc, path_help)->required();
    a = std::make_shared<FileArgs>();
    c = verb(*files, "rmdir", "Delete an empty directory (22 15)", g, exit_code, a, &run_rmdir);
    c->add_option("dir", a->plc, path_help)->required();

    a = std::make_shared<FileArgs>();
    c = verb(*files, "format", "Erase a file device (22 04)", g, exit_code, a, &run_format);
    c->add_option("device", a->plc, "card or em")->required();
    c->add_flag("--yes", a->yes, "Confirm erasing every file");

    const std::string what_help =
        "Word address (D100), parameter area (plc-setup, io-table, "
        "routing, cpu-bus) or program";
    using Run = int (*)(const GlobalOptions&, const FileArgs&, Output&);
    struct {
        const char* name;
        const char* help;
        Run run;
    } transfers[] = {{"save", "Save an area to a new PLC file (22 0A/0B/0C)", &run_save},
                     {"load", "Load a PLC file into an area (22 0A/0B/0C)", &run_load},
                     {"compare", "Compare a PLC file with an area (22 0A/0B/0C)", &run_compare}};
    for (const auto& t : transfers) {
        a = std::make_shared<FileArgs>();
        c = verb(*files, t.name, t.help, g, exit_code, a, t.run);
        // One list, read by transfer_arguments(): its messages say what goes where.
        c->add_option("args", a->paths,
                      t.run == &run_save ? "WHAT PLCFILE [COUNT] or WHAT COUNT PLCFILE"
                                         : "PLCFILE WHAT [COUNT]")
            ->description(std::string(what_help) + "; COUNT: words (word addresses only)");
    }
    add_cassette_verbs(*files, g, exit_code);
}

}  // namespace fins::cli
