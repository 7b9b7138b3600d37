// `fins` verbs for 02 xx parameter areas and 02 40 loop control (03 xx program area:
// verbs_program_area.cpp) (docs/commands.md, parameter and program areas):
//   param-read AREA [START] [COUNT]       02 01 in blocks of 498 words
//   param-write AREA START WORD...        02 02; whole areas are read, patched and
//                                         rewritten from word 0 (5-3-7), bit 15 on the
//                                         block holding the last word
//   param-clear AREA                      02 03 over the whole area
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
#include "cli/fins/verb_support.hpp"
#include "fins/commands/loop_control.hpp"
#include "fins/commands/parameter_area.hpp"

namespace fins::cli {

namespace {

std::string area_names() {
    std::string s;
    for (const auto& a : parameter_area_table())
        s += fmt::format("{}{} ({:04X})", s.empty() ? "" : ", ", a.id, a.code);
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
    if (!r) {
        // The Loop Control Board's own meanings of the codes (CS LCB manual 6-3, 02 40).
        if (r.error() == make_error_code(EndCode::area_classification_missing))
            out.explain(EndCode::area_classification_missing,
                        fmt::format("block {:03} is not a registered function block", *block));
        else if (r.error() == make_error_code(EndCode::address_range_error))
            out.explain(EndCode::address_range_error,
                        fmt::format("none of the ITEMs exists in block {:03}", *block));
        return out.failure(r.error(), fmt::format("loop-read block {}", *block));
    }
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

    add_program_area_verbs(app, g, exit_code);

    auto l = std::make_shared<LoopArgs>();
    c = verb(app, "loop-read", "Read ITEMs of a loop-control function block (02 40)", g, exit_code,
             l, &run_loop_read);
    c->add_option("block", l->block, "Function block address 0-999")->required();
    c->add_option("items", l->items, "ITEM numbers 0-999")->required();
}

}  // namespace fins::cli
