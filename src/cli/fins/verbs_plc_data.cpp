// `fins` verbs for 02 xx parameter areas, 03 xx program area, 02 40 loop control
// (README (parameter and program areas)):
//   param-read AREA [START] [COUNT]       02 01 in blocks of 498 words
//   param-write AREA START WORD...        02 02; whole areas are read, patched and
//                                         rewritten from word 0 (5-3-7), bit 15 on the
//                                         block holding the last word
//   param-clear AREA                      02 03 over the whole area
//   program-read [START] [BYTES]          03 06 in blocks of 992 bytes, to bit 15
//   program-write FILE                    03 07 in blocks of 996 bytes, bit 15 on the last
//   program-clear [--with-interrupt-tasks] 03 08
//   loop-read BLOCK ITEM...               02 40
// Numbers are decimal or 0x-prefixed hex. Exit codes as every verb: 0, 2, 3, 4.
#include <algorithm>
#include <array>
#include <cctype>
#include <charconv>
#include <fstream>
#include <iterator>
#include <memory>
#include <optional>
#include <string>
#include <variant>
#include <vector>

#include <fmt/core.h>

#include "cli/fins/commands.hpp"
#include "fins/commands/loop_control.hpp"
#include "fins/commands/parameter_area.hpp"
#include "fins/commands/program_area.hpp"

namespace fins::cli {

namespace {

std::optional<std::uint32_t> parse_number(const std::string& text, std::uint32_t max) {
    std::string_view s = text;
    int base = 10;
    if (s.size() > 2 && s[0] == '0' && (s[1] == 'x' || s[1] == 'X')) {
        base = 16;
        s.remove_prefix(2);
    }
    std::uint32_t v = 0;
    const auto [end, ec] = std::from_chars(s.data(), s.data() + s.size(), v, base);
    if (s.empty() || ec != std::errc{} || end != s.data() + s.size() || v > max)
        return std::nullopt;
    return v;
}

std::string area_names() {
    std::string s;
    for (const auto& a : parameter_area_table())
        s += fmt::format("{}{} ({:04X})", s.empty() ? "" : ", ", a.id, a.code);
    return s;
}

std::string hex_text(Bytes b) {
    std::string s;
    for (auto byte : b)
        s += fmt::format("{:02X}", byte);
    return s;
}

struct ParamArgs {
    std::string area;
    std::string start;
    std::string count;
    std::vector<std::string> words;
};

// Reads `count` words from `start` in blocks of 498 (never past the area's end).
Result<std::vector<std::uint16_t>> read_words(Client& client, const ParameterAreaInfo& area,
                                              std::uint32_t start, std::uint32_t count) {
    std::vector<std::uint16_t> words;
    words.reserve(count);
    Progress progress(fmt::format("param-read {}", area.id), count, "words");
    while (words.size() < count) {
        // 02 01 answers area, start, count (6 bytes), then the words.
        const auto n = std::min(fit(max_parameter_words, client.max_response_data(), 6, 2),
                                count - words.size());
        const ParameterAreaRead command{area.code, static_cast<std::uint16_t>(start + words.size()),
                                        static_cast<std::uint16_t>(n), false};
        auto r = client.send(command);
        if (!r) return Unexpected(r.error());
        if (r->count != n) return Unexpected(make_error_code(ClientError::malformed_response));
        words.insert(words.end(), r->words.begin(), r->words.end());
        progress.update(words.size());
    }
    return words;
}

// Writes `words` from `start` in blocks of 498, bit 15 on the block ending at the last word.
Result<std::size_t> write_words(Client& client, const ParameterAreaInfo& area, std::uint32_t start,
                                const std::vector<std::uint16_t>& words) {
    std::size_t done = 0;
    std::size_t blocks = 0;
    std::vector<std::uint8_t> bytes;
    Progress progress(fmt::format("param-write {}", area.id), words.size(), "words");
    while (done < words.size()) {
        const auto n =
            std::min(fit(max_parameter_words, client.max_parameters(), 6, 2), words.size() - done);
        bytes.clear();
        for (std::size_t i = 0; i < n; ++i) {
            bytes.push_back(static_cast<std::uint8_t>(words[done + i] >> 8));
            bytes.push_back(static_cast<std::uint8_t>(words[done + i]));
        }
        const auto first = start + done;
        const ParameterAreaWrite command{area.code, static_cast<std::uint16_t>(first),
                                         static_cast<std::uint16_t>(n), first + n == area.words,
                                         bytes};
        if (auto r = client.send(command); !r) return Unexpected(r.error());
        done += n;
        ++blocks;
        progress.update(done);
    }
    return blocks;
}

// AREA [START] [COUNT] -> area and a range inside it, or a usage error.
const ParameterAreaInfo* parse_area(const ParamArgs& a, Output& out, int& rc, std::uint32_t& start,
                                    std::uint32_t& count, std::uint32_t fixed_count = 0) {
    const auto* area = find_parameter_area(a.area);
    if (area == nullptr) {
        rc = out.usage(fmt::format("unknown parameter area '{}': use {}", a.area, area_names()));
        return nullptr;
    }
    auto s = a.start.empty() ? std::optional<std::uint32_t>(0) : parse_number(a.start, 0xFFFF);
    if (!s || *s >= area->words) {
        rc = out.usage(fmt::format("START '{}' is not a word of {} (0-{})", a.start, area->id,
                                   area->words - 1));
        return nullptr;
    }
    start = *s;
    auto c = fixed_count != 0  ? std::optional<std::uint32_t>(fixed_count)
             : a.count.empty() ? std::optional<std::uint32_t>(area->words - start)
                               : parse_number(a.count, 0xFFFF);
    if (!c || *c == 0 || start + *c > area->words) {
        rc = out.usage(fmt::format("{} holds words 0-{}: {} words from {} do not fit", area->id,
                                   area->words - 1, c ? *c : 0, start));
        return nullptr;
    }
    count = *c;
    return area;
}

int run_param_read(const GlobalOptions& g, const ParamArgs& a, Output& out) {
    int rc = exit_ok;
    std::uint32_t start = 0;
    std::uint32_t count = 0;
    const auto* area = parse_area(a, out, rc, start, count);
    if (area == nullptr) return rc;
    auto client = open_client(g, out, rc);
    if (!client) return rc;
    auto words = read_words(*client, *area, start, count);
    if (!words) return out.failure(words.error(), fmt::format("param-read {}", area->id));
    std::string text = fmt::format("{} ({:04X}) words {:04X}-{:04X}\n", area->name, area->code,
                                   start, start + count - 1);
    for (std::size_t i = 0; i < words->size(); ++i) {
        if (i % 8 == 0) text += fmt::format("{}{:04X} ", i ? "\n" : "", start + i);
        text += fmt::format(" {:04X}", (*words)[i]);
    }
    text += "\n";
    out.print({{"area", fmt::format("{:04X}", area->code)},
               {"name", area->name},
               {"start", start},
               {"count", count},
               {"last_word", start + count == area->words},
               {"words", *words}},
              text);
    return exit_ok;
}

int run_param_write(const GlobalOptions& g, const ParamArgs& a, Output& out) {
    auto parsed = parse_words(Format::uint16, a.words);
    if (auto* e = std::get_if<ParseError>(&parsed)) return out.usage(e->message);
    const auto& words = std::get<std::vector<std::uint16_t>>(parsed);
    int rc = exit_ok;
    std::uint32_t start = 0;
    std::uint32_t count = 0;
    const auto* area =
        parse_area(a, out, rc, start, count, static_cast<std::uint32_t>(words.size()));
    if (area == nullptr) return rc;
    auto client = open_client(g, out, rc);
    if (!client) return rc;
    const auto context = fmt::format("param-write {}", area->id);
    Result<std::size_t> blocks;
    std::size_t transferred = words.size();
    if (area->whole_area) {
        // 5-3-7: the area is written whole, so patch a fresh copy of it.
        auto all = read_words(*client, *area, 0, area->words);
        if (!all) return out.failure(all.error(), context);
        std::copy(words.begin(), words.end(), all->begin() + start);
        transferred = all->size();
        blocks = write_words(*client, *area, 0, *all);
    } else {
        blocks = write_words(*client, *area, start, words);
    }
    if (!blocks) return out.failure(blocks.error(), context);
    out.print({{"area", fmt::format("{:04X}", area->code)},
               {"start", start},
               {"written", words.size()},
               {"transferred", transferred},
               {"blocks", *blocks}},
              fmt::format("wrote {} at {} {:04X} ({} sent in {})\n", plural(words.size(), "word"),
                          area->id, start, plural(transferred, "word"), plural(*blocks, "block")));
    return exit_ok;
}

int run_param_clear(const GlobalOptions& g, const ParamArgs& a, Output& out) {
    const auto* area = find_parameter_area(a.area);
    if (area == nullptr)
        return out.usage(fmt::format("unknown parameter area '{}': use {}", a.area, area_names()));
    int rc = exit_ok;
    auto client = open_client(g, out, rc);
    if (!client) return rc;
    if (auto r = client->send(ParameterAreaClear{area->code, 0, area->words, false, 0}); !r)
        return out.failure(r.error(), fmt::format("param-clear {}", area->id));
    out.print(
        {{"area", fmt::format("{:04X}", area->code)}, {"cleared", true}, {"count", area->words}},
        fmt::format("cleared {} ({:04X}), {} words\n", area->name, area->code, area->words));
    return exit_ok;
}

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
    std::string digits;
    for (char c : raw)
        if (!std::isspace(static_cast<unsigned char>(c))) digits += c;
    if (digits.size() % 2 != 0) return std::nullopt;
    std::vector<std::uint8_t> data(digits.size() / 2);
    for (std::size_t i = 0; i < data.size(); ++i) {
        const char* first = digits.data() + 2 * i;
        const auto [end, ec] = std::from_chars(first, first + 2, data[i], 16);
        if (ec != std::errc{} || end != first + 2) return std::nullopt;
    }
    return data;
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

struct LoopArgs {
    std::string block;
    std::vector<std::string> items;
};

int run_loop_read(const GlobalOptions& g, const LoopArgs& a, Output& out) {
    FunctionBlockItemRead command;
    const auto block = parse_number(a.block, max_function_block);
    if (!block) return out.usage(fmt::format("BLOCK '{}' is not 0-999", a.block));
    command.block = static_cast<std::uint16_t>(*block);
    // 2,002-byte command: 6 bytes of code, block and count, then 2 per ITEM.
    if (a.items.size() > (max_loop_command_bytes - min_loop_command_bytes) / 2)
        return out.usage("too many ITEMs for one 02 40 command");
    for (const auto& text : a.items) {
        const auto item = parse_number(text, max_item_number);
        if (!item) return out.usage(fmt::format("ITEM '{}' is not 0-999", text));
        command.items.push_back(static_cast<std::uint16_t>(*item));
    }
    int rc = exit_ok;
    // The Loop Control Board is the Inner Board, unit E1, of the addressed node unless
    // --dest names another unit.
    GlobalOptions board = g;
    if (board.dest.empty()) board.dest = fmt::format("0.0.{}", inner_board_unit);
    auto client = open_client(board, out, rc);
    if (!client) return rc;
    auto r = client->send(command);
    if (!r) return out.failure(r.error(), fmt::format("loop-read block {}", *block));
    nlohmann::json items = nlohmann::json::array();
    std::string text = fmt::format("block {:03}: {} of {} ITEMs read\n", *block, r->items.size(),
                                   command.items.size());
    for (const auto& item : r->items) {
        std::uint64_t value = 0;
        for (auto byte : item.data)
            value = value << 8 | byte;
        nlohmann::json j{
            {"item", item.item}, {"length", item.data.size()}, {"hex", hex_text(item.data)}};
        if (item.data.size() <= 4) j["value"] = value;
        items.push_back(j);
        text += fmt::format("ITEM {:03}  {} bytes  {}  {}\n", item.item, item.data.size(),
                            hex_text(item.data), value);
    }
    out.print({{"block", *block}, {"read", r->items.size()}, {"items", items}}, text);
    return exit_ok;
}

// Registers a verb whose callback, run once parsing is done, stores `run`'s exit code.
template <class Args>
CLI::App* verb(CLI::App& app, const char* name, const char* help, const GlobalOptions& g,
               int& exit_code, const std::shared_ptr<Args>& args,
               int (*run)(const GlobalOptions&, const Args&, Output&)) {
    auto* c = app.add_subcommand(name, help);
    c->callback([&g, &exit_code, args, run] {
        Output out{g.json};
        exit_code = run(g, *args, out);
    });
    return c;
}

}  // namespace

void add_plc_data_verbs(CLI::App& app, const GlobalOptions& g, int& exit_code) {
    const std::string area_help = "Parameter area: " + area_names();
    auto p = std::make_shared<ParamArgs>();
    auto* c = verb(app, "param-read", "Read parameter area words (02 01)", g, exit_code, p,
                   &run_param_read);
    c->add_option("area", p->area, area_help)->required();
    c->add_option("start", p->start, "First word (default 0)");
    c->add_option("count", p->count, "Number of words (default: to the end of the area)");

    p = std::make_shared<ParamArgs>();
    c = verb(app, "param-write", "Write parameter area words (02 02)", g, exit_code, p,
             &run_param_write);
    c->add_option("area", p->area, area_help)->required();
    c->add_option("start", p->start, "First word")->required();
    c->add_option("words", p->words, "Word values (decimal or 0x hex)")->required();

    p = std::make_shared<ParamArgs>();
    c = verb(app, "param-clear", "Clear a whole parameter area (02 03)", g, exit_code, p,
             &run_param_clear);
    c->add_option("area", p->area, area_help)->required();

    auto r = std::make_shared<ProgramArgs>();
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

    auto l = std::make_shared<LoopArgs>();
    c = verb(app, "loop-read", "Read ITEMs of a loop-control function block (02 40)", g, exit_code,
             l, &run_loop_read);
    c->add_option("block", l->block, "Function block address 0-999")->required();
    c->add_option("items", l->items, "ITEM numbers 0-999")->required();
}

}  // namespace fins::cli
