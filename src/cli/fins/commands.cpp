#include "cli/fins/commands.hpp"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <memory>
#include <variant>

#include <fmt/core.h>

#include "codec/hex.hpp"
#include "fins/address.hpp"
#include "fins/address_names.hpp"
#include "fins/client.hpp"
#include "fins/commands/memory_area.hpp"
#include "fins/memory_area.hpp"

namespace fins::cli {

std::string bad_address(const std::string& text, std::error_code ec) {
    if (ec == make_error_code(AddressError::unknown_area))
        return fmt::format("bad address '{}': unknown memory area; the areas are {}", text,
                           area_names());
    return fmt::format("bad address '{}': {}", text, ec.message());
}

namespace {

std::optional<Address> address_or_usage(const std::string& text, Output& out, int& exit_code) {
    auto a = parse_address(text);
    if (!a) {
        exit_code = out.usage(bad_address(text, a.error()));
        return std::nullopt;
    }
    return *a;
}

// The address `n` elements after `a` (bits step bit by bit, words word by word).
Address advance(Address a, std::size_t n, bool bits) {
    if (bits && a.bit) {
        const std::size_t total = a.word * 16u + *a.bit + n;
        a.word = static_cast<std::uint16_t>(total / 16);
        a.bit = static_cast<std::uint8_t>(total % 16);
    } else {
        a.word = static_cast<std::uint16_t>(a.word + n);
    }
    return a;
}

std::string hex_bytes(Bytes b) {
    std::string s;
    for (std::size_t i = 0; i < b.size(); ++i)
        s += fmt::format("{}{:02X}", i ? " " : "", b[i]);
    return s;
}

std::optional<std::vector<std::uint8_t>> parse_hex(const std::vector<std::string>& parts) {
    std::string text;
    for (const auto& p : parts)
        text += p;
    return hex::parse_bytes(text, " :");
}

}  // namespace

namespace {

// The words `count` elements from `start` span must lie inside the area as W342 5-2-2
// sizes it; a request past that is the caller's mistake, told before anything is sent.
// (A profile with a smaller area still answers 1104 itself.)
std::optional<std::string> past_the_end(const Address& start, std::size_t count, bool bits,
                                        const std::string& text) {
    if (count == 0) return std::nullopt;
    const std::size_t first = start.word;
    const std::size_t last =
        bits && start.bit ? (first * 16 + *start.bit + count - 1) / 16 : first + count - 1;
    const std::uint16_t max = max_word(start.area);
    if (last <= max) return std::nullopt;
    Address end = start;
    end.word = max;
    end.bit.reset();
    return fmt::format("{}: {} from {} run past {}, the last word of the area", text,
                       plural(count, bits ? "bit" : "word"), format_address(start),
                       format_address(end));
}

// Reads `count` elements from `mem` in blocks of 999 (5-3-2), or what one answer holds
// (Host Link: 538 bytes, 269 words), noting CPU error flags.
Result<std::vector<std::uint8_t>> read_elements(Client& client, const MemoryAddress& mem,
                                                std::size_t count, bool bit_steps, Output& out,
                                                const std::string& what) {
    const std::size_t size = element_size(mem.area_code);
    std::vector<std::uint8_t> data;
    data.reserve(count * size);
    Progress progress(what, count, bit_steps || size == 1 ? "bits" : "words");
    const std::size_t block = std::min<std::size_t>(
        max_read_words, client.max_response_data() / std::max<std::size_t>(size, 1));
    for (std::size_t done = 0; done < count; done += block) {
        MemoryAddress at = mem;
        if (bit_steps) {
            const std::size_t linear = std::size_t{mem.word} * 16 + mem.bit + done;
            at.word = static_cast<std::uint16_t>(linear / 16);
            at.bit = static_cast<std::uint8_t>(linear % 16);
        } else {
            at.word = static_cast<std::uint16_t>(mem.word + done);
        }
        const auto n = std::min<std::size_t>(block, count - done);
        auto r = send_noting_flags(client, MemoryAreaRead{at, static_cast<std::uint16_t>(n)}, out);
        if (!r) return Unexpected(r.error());
        data.insert(data.end(), r->data.begin(), r->data.end());
        progress.update(done + n);
    }
    return data;
}

// The first word that is not BCD, for the message.
std::string not_bcd(const Address& start, const std::vector<std::uint16_t>& words) {
    for (std::size_t i = 0; i < words.size(); ++i) {
        const auto w = words[i];
        if ((w & 0xF) > 9 || (w >> 4 & 0xF) > 9 || (w >> 8 & 0xF) > 9 || (w >> 12) > 9)
            return fmt::format("{} holds 0x{:04X}, which is not BCD (use --as hex)",
                               format_address(advance(start, i, false)), w);
    }
    return "the words are not BCD";
}

}  // namespace

int run_read(const GlobalOptions& g, const ReadArgs& a, Format f, Output& out) {
    int rc = exit_ok;
    auto start = address_or_usage(a.address, out, rc);
    if (!start) return rc;
    const bool flag_area = start->area == Area::timer || start->area == Area::counter;
    // Task flags have no word form: TK2 reads as a bit whatever --as says by default.
    const bool bit_only = start->area == Area::task_flag;
    const bool bits = f == Format::bits || ((start->bit || bit_only) && f == Format::uint16);
    if ((start->bit || bit_only) && !bits)
        return out.usage(fmt::format("{} names a bit: use --as bits", a.address));
    if (f == Format::bits && !start->bit && !flag_area && !bit_only) {
        if (start->area == Area::index_register || start->area == Area::data_register)
            return out.usage(
                fmt::format("{} has no bits to read: IR and DR are word access only", a.address));
        return out.usage(fmt::format(
            "{} is a word: name a bit ({}.00) to read bits, or use --as hex for the word",
            a.address, format_address(*start)));
    }
    // Index registers are 32-bit elements (5-2-2, element size 4): one value each.
    const bool wide = start->area == Area::index_register;
    if (wide && f != Format::uint16 && f != Format::uint32 && f != Format::int32 &&
        f != Format::hex)
        return out.usage(
            fmt::format("{} is a 32-bit index register: use --as uint32, int32 or hex", a.address));
    const std::size_t step = words_per_value(f);
    const std::size_t elements = bits || wide          ? a.count
                                 : f == Format::string ? a.count
                                                       : a.count * step;
    if (auto problem = past_the_end(*start, elements, bits, "read")) return out.usage(*problem);
    auto mem = to_memory_address(*start, bits ? Access::bit : Access::word);
    if (!mem) return out.usage(fmt::format("{}: {}", a.address, mem.error().message()));
    auto client = open_client(g, out, rc);
    if (!client) return rc;

    const auto context = fmt::format("read {}", a.address);
    auto data =
        read_elements(*client, *mem, elements, bits && start->bit.has_value(), out, context);
    if (!data) return out.failure(data.error(), context);
    nlohmann::json values = nlohmann::json::array();
    std::string text;
    if (bits) {
        for (std::size_t i = 0; i < data->size(); ++i) {
            const int bit = ((*data)[i] & 1) != 0 ? 1 : 0;  // bit 1 is the forced flag
            values.push_back(bit);
            text += fmt::format("{}  {}\n", format_address(advance(*start, i, true)), bit);
        }
    } else if (wide) {
        for (std::size_t i = 0; i + 3 < data->size(); i += 4) {
            const std::uint32_t v = std::uint32_t{(*data)[i]} << 24 |
                                    std::uint32_t{(*data)[i + 1]} << 16 |
                                    std::uint32_t{(*data)[i + 2]} << 8 | (*data)[i + 3];
            const std::string shown = f == Format::hex ? fmt::format("0x{:08X}", v)
                                      : f == Format::int32
                                          ? fmt::format("{}", static_cast<std::int32_t>(v))
                                          : fmt::format("{}", v);
            if (f == Format::hex)
                values.push_back(shown);
            else if (f == Format::int32)
                values.push_back(static_cast<std::int32_t>(v));
            else
                values.push_back(v);
            text += fmt::format("{}  {}\n", format_address(advance(*start, i / 4, false)), shown);
        }
    } else {
        std::vector<std::uint16_t> words;
        for (std::size_t i = 0; i + 1 < data->size(); i += 2)
            words.push_back(static_cast<std::uint16_t>((*data)[i] << 8 | (*data)[i + 1]));
        auto printed = print_words(f, words);
        if (!printed)
            return out.usage(f == Format::bcd ? not_bcd(*start, words) : printed.error().message());
        for (std::size_t i = 0; i < printed->size(); ++i) {
            values.push_back((*printed)[i].json);
            text += fmt::format("{}  {}\n", format_address(advance(*start, i * step, false)),
                                (*printed)[i].text);
        }
    }
    out.print({{"address", format_address(*start)},
               {"as", bits ? "bits" : std::string(format_name(f))},
               {"values", values}},
              text);
    return exit_ok;
}

int run_write(const GlobalOptions& g, const WriteArgs& a, Format f, Output& out) {
    int rc = exit_ok;
    auto start = address_or_usage(a.address, out, rc);
    if (!start) return rc;
    const bool bit_only = start->area == Area::task_flag;
    const bool bits = f == Format::bits || ((start->bit || bit_only) && f == Format::uint16);
    if ((start->bit || bit_only) && !bits)
        return out.usage(fmt::format("{} names a bit: use --as bits", a.address));
    if (bits && !start->bit && !bit_only)
        return out.usage(fmt::format("{} is a word: name a bit ({}.00) to write bits", a.address,
                                     format_address(*start)));
    if (start->area == Area::index_register)
        return out.usage(
            fmt::format("{} is a 32-bit index register: write takes word areas "
                        "(`fins raw 0102 DC...` sends any MEMORY AREA WRITE)",
                        a.address));
    auto parsed = parse_words(bits ? Format::bits : f, a.values);
    if (auto* e = std::get_if<ParseError>(&parsed)) return out.usage(e->message);
    const auto& words = std::get<std::vector<std::uint16_t>>(parsed);
    if (auto problem = past_the_end(*start, words.size(), bits, "write"))
        return out.usage(*problem);
    auto client = open_client(g, out, rc);
    if (!client) return rc;
    Result<void> r;
    if (bits) {
        std::vector<bool> b(words.begin(), words.end());
        r = client->write_bits(*start, b);
    } else {
        r = client->write_words(*start, words);
    }
    if (!r) return out.failure(r.error(), fmt::format("write {}", a.address));
    out.print({{"address", format_address(*start)},
               {"as", bits ? "bits" : std::string(format_name(f))},
               {"written", words.size()}},
              fmt::format("wrote {} at {}\n", plural(words.size(), bits ? "bit" : "word"),
                          format_address(*start)));
    return exit_ok;
}

int run_fill(const GlobalOptions& g, const FillArgs& a, Output& out) {
    int rc = exit_ok;
    auto start = address_or_usage(a.address, out, rc);
    if (!start) return rc;
    if (start->bit) return out.usage(fmt::format("fill takes a word address, not {}", a.address));
    auto parsed = parse_words(Format::uint16, {a.value});
    if (auto* e = std::get_if<ParseError>(&parsed)) return out.usage(e->message);
    const auto value = std::get<std::vector<std::uint16_t>>(parsed).at(0);
    if (auto problem = past_the_end(*start, a.count, false, "fill")) return out.usage(*problem);
    auto client = open_client(g, out, rc);
    if (!client) return rc;
    if (auto r = client->fill(*start, a.count, value); !r)
        return out.failure(r.error(), fmt::format("fill {}", a.address));
    out.print({{"address", format_address(*start)}, {"count", a.count}, {"value", value}},
              fmt::format("filled {} at {} with 0x{:04X}\n", plural(a.count, "word"),
                          format_address(*start), value));
    return exit_ok;
}

int run_transfer(const GlobalOptions& g, const TransferArgs& a, Output& out) {
    int rc = exit_ok;
    auto from = address_or_usage(a.from, out, rc);
    if (!from) return rc;
    auto to = address_or_usage(a.to, out, rc);
    if (!to) return rc;
    if (from->bit || to->bit) return out.usage("transfer takes word addresses");
    if (auto problem = past_the_end(*from, a.count, false, "transfer from"))
        return out.usage(*problem);
    if (auto problem = past_the_end(*to, a.count, false, "transfer to")) return out.usage(*problem);
    auto client = open_client(g, out, rc);
    if (!client) return rc;
    if (auto r = client->transfer(*from, *to, a.count); !r)
        return out.failure(r.error(), fmt::format("transfer {} -> {}", a.from, a.to));
    out.print({{"from", format_address(*from)}, {"to", format_address(*to)}, {"count", a.count}},
              fmt::format("copied {} from {} to {}\n", plural(a.count, "word"),
                          format_address(*from), format_address(*to)));
    return exit_ok;
}

int run_read_multi(const GlobalOptions& g, const ReadMultiArgs& a, Output& out) {
    int rc = exit_ok;
    std::vector<Address> addresses;
    std::vector<MemoryAddress> items;
    for (const auto& text : a.addresses) {
        auto addr = address_or_usage(text, out, rc);
        if (!addr) return rc;
        auto mem = to_memory_address(*addr);
        if (!mem) return out.usage(fmt::format("{}: {}", text, mem.error().message()));
        addresses.push_back(*addr);
        items.push_back(*mem);
    }
    auto client = open_client(g, out, rc);
    if (!client) return rc;
    std::vector<std::uint32_t> read;
    for (std::size_t offset = 0; offset < items.size(); offset += max_multiple_read_elements) {
        MultipleMemoryAreaRead command;
        const auto n = std::min(max_multiple_read_elements, items.size() - offset);
        command.items.assign(items.begin() + static_cast<std::ptrdiff_t>(offset),
                             items.begin() + static_cast<std::ptrdiff_t>(offset + n));
        auto r = send_noting_flags(*client, command, out);
        if (!r) return out.failure(r.error(), "read-multi");
        for (const auto& item : r->items)
            read.push_back(item.value);
    }
    nlohmann::json items_json = nlohmann::json::array();
    std::string text;
    // Addresses of every length in one column: the values line up.
    std::size_t width = 0;
    for (const auto& address : addresses)
        width = std::max(width, format_address(address).size());
    for (std::size_t i = 0; i < read.size() && i < addresses.size(); ++i) {
        const auto name = format_address(addresses[i]);
        items_json.push_back({{"address", name}, {"value", read[i]}});
        text += fmt::format("{:<{}}  {}\n", name, width, read[i]);
    }
    out.print({{"items", items_json}}, text);
    return exit_ok;
}

int run_raw(const GlobalOptions& g, const RawArgs& a, Output& out) {
    auto code = parse_hex({a.command});
    if (!code || code->size() != 2)
        return out.usage(fmt::format("command '{}' is not 4 hex digits (MRC SRC)", a.command));
    auto params = parse_hex(a.parameters);
    if (!params) return out.usage("parameters are not whole hex bytes");
    if (params->size() > max_parameter_size)
        return out.usage(fmt::format("parameters are {} bytes; a FINS command carries at most {}",
                                     params->size(), max_parameter_size));
    int rc = exit_ok;
    auto client = open_client(g, out, rc);
    if (!client) return rc;
    const CommandCode command{(*code)[0], (*code)[1]};
    if (a.no_response) {
        if (auto r = client->send_no_response(command, *params); !r)
            return out.failure(r.error(), "raw");
        out.print({{"sent", true}}, "sent (no response requested)\n");
        return exit_ok;
    }
    auto r = client->send_raw(command, *params);
    if (!r) return out.failure(r.error(), "raw");
    const auto end = static_cast<std::uint16_t>(r->code.end_code());
    const auto* info = find_end_code(end);
    const std::string name = info ? std::string(info->name) : "unknown end code";
    nlohmann::json doc{{"command", fmt::format("{:04X}", command.value())},
                       {"end_code", fmt::format("{:04X}", r->code.raw())},
                       {"name", name},
                       {"ok", r->code.ok()},
                       {"fatal_cpu_error", r->code.fatal_cpu_error()},
                       {"non_fatal_cpu_error", r->code.non_fatal_cpu_error()},
                       {"source", node_text(r->header.source)},
                       {"sid", r->header.service_id},
                       {"data", hex_bytes(r->data)}};
    std::string text = fmt::format("end code {:04X} {}", r->code.raw(), name);
    if (r->code.non_fatal_cpu_error()) text += " [non-fatal CPU error]";
    if (r->code.fatal_cpu_error()) text += " [fatal CPU error]";
    if (r->relay) {
        doc["relay_error"] = {{"network", r->relay->network}, {"node", r->relay->node}};
        text +=
            fmt::format(" [relay error at network {} node {}]", r->relay->network, r->relay->node);
    }
    text += fmt::format("\nfrom {} sid {:02X}\ndata ({} bytes): {}\n", node_text(r->header.source),
                        r->header.service_id, r->data.size(), hex_bytes(r->data));
    out.print(doc, text);
    return r->code.ok() ? exit_ok : exit_end_code;
}

}  // namespace fins::cli
