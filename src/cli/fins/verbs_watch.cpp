// `fins watch ADDRESS... [--as TYPE [--words N]] [--interval S] [--count N] [--duration S]`:
// polls the addresses with one 01 04 MULTIPLE MEMORY AREA READ per turn (W342 5-3-5; split
// above 167 elements, or what one Host Link frame holds) and prints each value the first
// time and whenever it changes. --as takes `fins read`'s formats (typed/value_format.hpp):
// a multi-word type reads its words from the address on (int32: D100 and D101), string
// reads --words words; without --as a word prints unsigned, a bit 0/1, T/C the PV:
//   text    "HH:MM:SS.mmm  D100  5" (host local time)
//   --json  one object per line: {"time": "YYYY-MM-DD HH:MM:SS.mmm", "address", "value"}
// It ends after N polls (--count), after S seconds (--duration), or on Ctrl-C / SIGTERM,
// each with exit 0; a failed poll ends it with that failure's exit code (3 or 4).
// Ctrl-C and SIGTERM are taken between polls (StopRequest), so a signal never interrupts
// a request half way and the output ends on a whole line.
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <ctime>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <fmt/core.h>

#include "cli/fins/commands.hpp"
#include "cli/fins/stop_request.hpp"
#include "cli/fins/verb_support.hpp"
#include "fins/address.hpp"
#include "fins/commands/memory_area.hpp"

namespace fins::cli {

namespace {

struct WatchArgs {
    std::vector<std::string> addresses;
    double interval_seconds = 1.0;
    unsigned count = 0;           // 0: no limit
    double duration_seconds = 0;  // 0: no limit
    std::string as;               // empty: the raw element
    unsigned words = 0;           // --as string: words per value
};

// One watched address: its elements' place in the poll's items and how they print.
struct Watched {
    Address address;
    std::size_t first = 0;
    std::size_t count = 1;
};

using Clock = std::chrono::steady_clock;

// Local wall-clock time with milliseconds: the date only in JSON (lines of a long run).
std::string now_text(bool with_date) {
    const auto now = std::chrono::system_clock::now();
    const std::time_t t = std::chrono::system_clock::to_time_t(now);
    const auto ms =
        std::chrono::duration_cast<std::chrono::milliseconds>(now.time_since_epoch()).count() %
        1000;
    std::tm tm{};
    ::localtime_r(&t, &tm);
    char buf[32];
    std::strftime(buf, sizeof buf, with_date ? "%Y-%m-%d %H:%M:%S" : "%H:%M:%S", &tm);
    return fmt::format("{}.{:03}", buf, ms);
}

// Appends the elements `a` is watched as to `items`, or says why it cannot be.
std::optional<std::string> add_elements(const Address& a, const std::string& text,
                                        const std::optional<Format>& f, unsigned string_words,
                                        std::vector<MemoryAddress>& items) {
    const bool bit_only = a.area == Area::task_flag;
    const bool flag_area = a.area == Area::timer || a.area == Area::counter;
    Access access = Access::natural;
    std::size_t n = 1;
    if (f == Format::bits) {
        if (!a.bit && !bit_only && !flag_area) {
            if (a.area == Area::index_register || a.area == Area::data_register)
                return fmt::format("{} has no bits to watch: IR and DR are word access only", text);
            return fmt::format("{} is a word: name a bit ({}.00) to watch bits", text,
                               format_address(a));
        }
        access = Access::bit;  // T/C: the completion flag
    } else if (f) {
        if (a.bit || bit_only) return fmt::format("{} names a bit: use --as bits", text);
        if (a.area == Area::index_register) {
            // One 32-bit element (W342 5-2-2, element size 4), as `fins read` shows it.
            if (f != Format::uint16 && f != Format::uint32 && f != Format::int32 &&
                f != Format::hex)
                return fmt::format("{} is a 32-bit index register: use --as uint32, int32 or hex",
                                   text);
        } else {
            n = f == Format::string ? string_words : words_per_value(*f);
            access = Access::word;
            if (std::size_t{a.word} + n - 1 > max_word(a.area)) {
                Address last = a;
                last.word = max_word(a.area);
                return fmt::format("{}: {} from {} run past {}, the last word of the area", text,
                                   plural(n, "word"), format_address(a), format_address(last));
            }
        }
    }
    for (std::size_t k = 0; k < n; ++k) {
        Address at = a;
        at.word = static_cast<std::uint16_t>(a.word + k);
        auto mem = to_memory_address(at, access);
        if (!mem) return fmt::format("{}: {}", text, mem.error().message());
        items.push_back(*mem);
    }
    return std::nullopt;
}

// One value as --as shows it; without --as the element as the PLC sent it.
Printed show(const std::optional<Format>& f, const Address& a, const std::uint32_t* raw,
             std::size_t count) {
    if (!f) return {fmt::format("{}", raw[0]), raw[0]};
    if (f == Format::bits) {
        const int bit = (raw[0] & 1U) != 0 ? 1 : 0;  // bit 1 is the forced flag
        return {fmt::format("{}", bit), bit};
    }
    if (a.area == Area::index_register) {
        if (f == Format::hex) {
            auto hex = fmt::format("0x{:08X}", raw[0]);
            return {hex, hex};
        }
        if (f == Format::int32) {
            const auto v = static_cast<std::int32_t>(raw[0]);
            return {fmt::format("{}", v), v};
        }
        return {fmt::format("{}", raw[0]), raw[0]};
    }
    std::vector<std::uint16_t> words;
    for (std::size_t i = 0; i < count; ++i)
        words.push_back(static_cast<std::uint16_t>(raw[i]));
    auto printed = print_words(*f, words);
    if (printed && !printed->empty()) return printed->front();
    // A pattern the format cannot show (0x12AB as bcd): the words, and null in JSON. The
    // watch goes on: the next change may be a valid value again.
    std::string text = fmt::format("not {}:", format_name(*f));
    for (const auto w : words)
        text += fmt::format(" 0x{:04X}", w);
    return {text, nullptr};
}

// One turn: every item in as few 01 04 requests as the link allows.
Result<std::vector<std::uint32_t>> poll(Client& client, const std::vector<MemoryAddress>& items) {
    const std::size_t per =
        std::max<std::size_t>(1, std::min({max_multiple_read_elements, client.max_parameters() / 4,
                                           client.max_response_data() / 5}));
    std::vector<std::uint32_t> values;
    values.reserve(items.size());
    for (std::size_t offset = 0; offset < items.size(); offset += per) {
        const auto n = std::min(per, items.size() - offset);
        MultipleMemoryAreaRead command;
        command.items.assign(items.begin() + static_cast<std::ptrdiff_t>(offset),
                             items.begin() + static_cast<std::ptrdiff_t>(offset + n));
        auto r = client.send(command);
        if (!r) return Unexpected(r.error());
        if (r->items.size() != n)
            return Unexpected(make_error_code(ClientError::malformed_response));
        for (const auto& item : r->items)
            values.push_back(item.value);
    }
    return values;
}

int run_watch(const GlobalOptions& g, const WatchArgs& a, Output& out) {
    std::optional<Format> format;
    if (!a.as.empty()) {
        format = parse_format(a.as);
        if (!format)
            return out.usage(fmt::format(
                "unknown --as format '{}' (int16 uint16 int32 uint32 float double bcd bcd32 "
                "string bits hex)",
                a.as));
    }
    if (format == Format::string && a.words == 0)
        return out.usage(
            "--as string needs --words N, the words of each value (2 characters a word)");
    if (a.words != 0 && format != Format::string)
        return out.usage("--words is the length of an --as string value");
    std::vector<Watched> watched;
    std::vector<MemoryAddress> items;
    for (const auto& text : a.addresses) {
        auto addr = parse_address(text);
        if (!addr) return out.usage(bad_address(text, addr.error()));
        const std::size_t first = items.size();
        if (auto why = add_elements(*addr, text, format, a.words, items)) return out.usage(*why);
        watched.push_back({*addr, first, items.size() - first});
    }
    // Before the client exists, so every thread it might start inherits the signal mask.
    StopRequest stop;

    int rc = exit_ok;
    auto client = open_client(g, out, rc);
    if (!client) return rc;
    const auto interval = std::chrono::duration_cast<Clock::duration>(
        std::chrono::duration<double>(a.interval_seconds));
    const auto start = Clock::now();
    const auto end = a.duration_seconds > 0
                         ? start + std::chrono::duration_cast<Clock::duration>(
                                       std::chrono::duration<double>(a.duration_seconds))
                         : Clock::time_point::max();
    std::vector<std::optional<std::vector<std::uint32_t>>> last(watched.size());
    for (unsigned turn = 0; a.count == 0 || turn < a.count; ++turn) {
        auto values = poll(*client, items);
        if (!values) return out.failure(values.error(), "watch");
        for (std::size_t i = 0; i < watched.size(); ++i) {
            const auto& w = watched[i];
            const auto* raw = values->data() + w.first;
            std::vector<std::uint32_t> now(raw, raw + w.count);
            if (last[i] == now) continue;
            last[i] = std::move(now);
            const auto name = format_address(w.address);
            const auto value = show(format, w.address, raw, w.count);
            out.print({{"time", now_text(true)}, {"address", name}, {"value", value.json}},
                      fmt::format("{}  {}  {}\n", now_text(false), name, value.text));
        }
        std::fflush(stdout);
        if (a.count != 0 && turn + 1 >= a.count) break;
        // Fixed rate: a slow poll shortens the next wait instead of shifting the rest.
        auto next = start + interval * (turn + 1);
        if (next > end) next = end;
        if (stop.requested_before(next) || Clock::now() >= end) break;
    }
    return exit_ok;
}

}  // namespace

void add_watch_verbs(CLI::App& app, const GlobalOptions& g, int& exit_code) {
    auto a = std::make_shared<WatchArgs>();
    auto* c = verb(app, "watch", "Poll addresses and print each change (01 04)", g, exit_code, a,
                   &run_watch);
    c->add_option("addresses", a->addresses, "Addresses, e.g. D100 CIO10.03 T5")->required();
    c->add_option("--as", a->as,
                  "Show values as int16 uint16 int32 uint32 float double bcd bcd32 string bits "
                  "hex (default: each word unsigned, each bit 0/1)");
    c->add_option("--words", a->words, "Words of each --as string value (2 characters a word)")
        ->check(CLI::Range(1U, 999U));
    c->add_option("--interval", a->interval_seconds, "Seconds between polls")
        ->capture_default_str()
        ->check(CLI::Range(0.01, 86400.0));
    c->add_option("--count", a->count, "Stop after N polls (default: no limit)")
        ->check(CLI::Range(1U, 1'000'000'000U));
    c->add_option("--duration", a->duration_seconds, "Stop after S seconds (default: no limit)")
        ->check(CLI::Range(0.001, 31'536'000.0));
}

}  // namespace fins::cli
