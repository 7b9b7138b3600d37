// `fins` verbs for the 03 xx program area (docs/commands.md, parameter and program areas):
//   program-read [START] [BYTES]          03 06 in blocks of 992 bytes, to bit 15
//   program-write FILE                    03 07 in blocks of 996 bytes, bit 15 on the last
//   program-clear [--with-interrupt-tasks] 03 08
// Numbers are decimal or 0x-prefixed hex. Exit codes as every verb: 0, 2, 3, 4.
#include <algorithm>
#include <array>
#include <fstream>
#include <iterator>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <fmt/core.h>

#include "cli/fins/commands.hpp"
#include "cli/fins/verb_support.hpp"
#include "codec/hex.hpp"
#include "fins/commands/program_area.hpp"

namespace fins::cli {

namespace {

struct ProgramArgs {
    std::string start;
    std::string bytes;
    std::string file;
    bool hex = false;
    bool interrupt_tasks = false;
};

std::optional<std::uint32_t> aligned_number(const std::string& text, std::uint32_t fallback) {
    if (text.empty()) return fallback;
    auto v = parse_number(text, 0xFFFFFFFF);
    if (!v || *v % program_alignment != 0) return std::nullopt;
    return v;
}

// One 03 06 block. A block that runs past the UM's end comes back cut, with bit 15 and
// end code 1104 (5-3-7's rule, which finsd also applies to the program area), so the
// answer is taken raw: 1104 with data is the end, not a failure.
Result<ProgramAreaReadResponse> read_block(Client& client, const ProgramAreaRead& command) {
    std::array<std::uint8_t, 8> parameters{};
    ByteWriter w(parameters);
    command.encode(w);
    auto r = client.send_raw(ProgramAreaRead::code, w.written());
    if (!r) return Unexpected(r.error());
    const auto code = r->code.end_code();
    const bool cut = code == EndCode::address_range_exceeded && !r->data.empty();
    if (!r->code.ok() && !cut) return Unexpected(make_error_code(code));
    auto block = command.decode_response(r->data);
    if (block && cut) block->last = true;  // nothing follows a cut block
    return block;
}

int run_program_read(const GlobalOptions& g, const ProgramArgs& a, Output& out) {
    const auto start = aligned_number(a.start, 0);
    const auto limit = aligned_number(a.bytes, 0xFFFFFFFC);
    if (!start || !limit || *limit == 0)
        return out.usage("START and BYTES are byte counts, multiples of 4 (5-3-10)");
    int rc = exit_ok;
    auto client = open_client(g, out, rc);
    if (!client) return rc;
    std::vector<std::uint8_t> data;
    bool last = false;
    // The UM's size is not known before bit 15: the default limit shows as "to the end".
    Progress progress("program-read", a.bytes.empty() ? 0 : *limit, "bytes");
    // Until bit 15 (the UM's last address) or BYTES; the UM is finite, so is this loop.
    while (!last && data.size() < *limit) {
        // 03 06 answers program number, address, count (8 bytes), then 4-byte steps.
        const auto n =
            std::min(fit(max_program_read_bytes / 4, client->max_response_data(), 8, 4) * 4,
                     *limit - data.size());
        const ProgramAreaRead command{program_number_all,
                                      static_cast<std::uint32_t>(*start + data.size()),
                                      static_cast<std::uint16_t>(n), false};
        auto r = read_block(*client, command);
        if (!r) return out.failure(r.error(), "program-read");
        if (r->data.empty() && !r->last)
            return out.failure(make_error_code(ClientError::malformed_response), "program-read");
        data.insert(data.end(), r->data.begin(), r->data.end());
        last = r->last;
        progress.update(data.size());
    }
    nlohmann::json doc{{"start", *start}, {"bytes", data.size()}, {"last", last}};
    if (!a.file.empty()) {
        std::ofstream f(a.file, std::ios::binary | std::ios::trunc);
        const std::string body =
            a.hex ? hex_text(data) + "\n" : std::string(data.begin(), data.end());
        if (!f.write(body.data(), static_cast<std::streamsize>(body.size())))
            return out.usage(fmt::format("cannot write '{}'", a.file));
        doc["file"] = a.file;
        out.print(doc, fmt::format("read {} from {:08X} into {}{}\n", plural(data.size(), "byte"),
                                   *start, a.file, last ? " (to the last address)" : ""));
        return exit_ok;
    }
    doc["data"] = hex_text(data);
    std::string text;
    for (std::size_t i = 0; i < data.size(); i += 16) {
        text += fmt::format("{:08X} ", *start + i);
        for (std::size_t j = i; j < std::min(data.size(), i + 16); ++j)
            text += fmt::format(" {:02X}", data[j]);
        text += "\n";
    }
    out.print(doc, text);
    return exit_ok;
}

std::optional<std::vector<std::uint8_t>> load_program(const ProgramArgs& a) {
    std::ifstream f(a.file, std::ios::binary);
    if (!f) return std::nullopt;
    std::string raw{std::istreambuf_iterator<char>(f), std::istreambuf_iterator<char>()};
    if (!a.hex) return std::vector<std::uint8_t>(raw.begin(), raw.end());
    // Pairs of hex digits; white space anywhere.
    return hex::parse_bytes(raw, " \t\n\r\v\f");
}

int run_program_write(const GlobalOptions& g, const ProgramArgs& a, Output& out) {
    const auto start = aligned_number(a.start, 0);
    if (!start) return out.usage("--start is a byte address, a multiple of 4 (5-3-11)");
    const auto data = load_program(a);
    if (!data) return out.usage(fmt::format("cannot read '{}'{}", a.file, a.hex ? " as hex" : ""));
    if (data->empty() || data->size() % program_alignment != 0)
        return out.usage(fmt::format("'{}' holds {} bytes: a program is a non-zero multiple of 4",
                                     a.file, data->size()));
    int rc = exit_ok;
    auto client = open_client(g, out, rc);
    if (!client) return rc;
    std::size_t done = 0;
    std::size_t blocks = 0;
    Progress progress("program-write", data->size(), "bytes");
    while (done < data->size()) {
        const auto n =
            std::min(fit(max_program_write_bytes / 4, client->max_parameters(), 8, 4) * 4,
                     data->size() - done);
        const ProgramAreaWrite command{
            program_number_all, static_cast<std::uint32_t>(*start + done),
            static_cast<std::uint16_t>(n), done + n == data->size(), Bytes(data->data() + done, n)};
        if (auto r = client->send(command); !r) return out.failure(r.error(), "program-write");
        done += n;
        ++blocks;
        progress.update(done);
    }
    out.print({{"start", *start}, {"bytes", done}, {"blocks", blocks}},
              fmt::format("wrote {} at {:08X} in {}\n", plural(done, "byte"), *start,
                          plural(blocks, "block")));
    return exit_ok;
}

int run_program_clear(const GlobalOptions& g, const ProgramArgs& a, Output& out) {
    int rc = exit_ok;
    auto client = open_client(g, out, rc);
    if (!client) return rc;
    const ProgramAreaClear command{program_number_all, a.interrupt_tasks
                                                           ? clear_with_interrupt_tasks
                                                           : clear_without_interrupt_tasks};
    if (auto r = client->send(command); !r) return out.failure(r.error(), "program-clear");
    out.print({{"cleared", true}, {"interrupt_tasks", a.interrupt_tasks}},
              fmt::format("program area cleared ({})\n",
                          a.interrupt_tasks ? "with interrupt tasks" : "cyclic task 0 only"));
    return exit_ok;
}

}  // namespace

void add_program_area_verbs(CLI::App& app, const GlobalOptions& g, int& exit_code) {
    std::shared_ptr<ProgramArgs> r;
    CLI::App* c = nullptr;
    r = std::make_shared<ProgramArgs>();
    c = verb(app, "program-read", "Read the program area (03 06)", g, exit_code, r,
             &run_program_read);
    c->add_option("start", r->start, "First byte address, multiple of 4 (default 0)");
    c->add_option("bytes", r->bytes, "Bytes to read, multiple of 4 (default: to the end)");
    c->add_option("--out", r->file, "Write the bytes to FILE instead of printing them");
    c->add_flag("--hex", r->hex, "With --out: write hex text instead of binary");

    r = std::make_shared<ProgramArgs>();
    c = verb(app, "program-write", "Write the program area from a file (03 07)", g, exit_code, r,
             &run_program_write);
    c->add_option("file", r->file, "Program image (binary, or hex text with --hex)")->required();
    c->add_option("--start", r->start, "First byte address, multiple of 4 (default 0)");
    c->add_flag("--hex", r->hex, "FILE holds hex text");

    r = std::make_shared<ProgramArgs>();
    c = verb(app, "program-clear", "Clear the program area (03 08)", g, exit_code, r,
             &run_program_clear);
    c->add_flag("--with-interrupt-tasks", r->interrupt_tasks,
                "Clear code 10: set up the interrupt tasks too (5-3-12)");
}

}  // namespace fins::cli
