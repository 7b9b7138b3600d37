#include "cli/fins/commands.hpp"

#include <charconv>
#include <chrono>
#include <cstdio>
#include <memory>
#include <variant>

#include <fmt/core.h>

#include "fins/address.hpp"
#include "fins/client.hpp"
#include "fins/memory_area.hpp"

namespace fins::cli {

namespace {

std::optional<NodeAddress> parse_node_address(const std::string& s) {
    unsigned parts[3] = {0, 0, 0};
    std::size_t i = 0;
    const char* p = s.data();
    const char* end = s.data() + s.size();
    while (i < 3) {
        auto [next, ec] = std::from_chars(p, end, parts[i]);
        if (ec != std::errc{} || parts[i] > 255) return std::nullopt;
        p = next;
        ++i;
        if (i < 3) {
            if (p == end || *p != '.') return std::nullopt;
            ++p;
        }
    }
    if (p != end || parts[0] > 127) return std::nullopt;
    return NodeAddress{static_cast<std::uint8_t>(parts[0]), static_cast<std::uint8_t>(parts[1]),
                       static_cast<std::uint8_t>(parts[2])};
}

// Connects, or prints why not and sets `exit_code`.
}  // namespace

std::unique_ptr<Client> open_client(const GlobalOptions& g, Output& out, int& exit_code) {
    ClientOptions o;
    o.host = g.host;
    o.port = g.port;
    o.protocol = g.tcp ? ClientOptions::Protocol::tcp : ClientOptions::Protocol::udp;
    o.timeout = std::chrono::milliseconds(static_cast<long>(g.timeout_seconds * 1000.0 + 0.5));
    o.retries = g.retries;
    if (!g.dest.empty()) {
        auto d = parse_node_address(g.dest);
        if (!d) {
            exit_code = out.usage(fmt::format("--dest '{}' is not NET.NODE.UNIT", g.dest));
            return nullptr;
        }
        o.destination = *d;
    }
    if (!g.source.empty()) {
        auto s = parse_node_address(g.source);
        if (!s) {
            exit_code = out.usage(fmt::format("--source '{}' is not NET.NODE.UNIT", g.source));
            return nullptr;
        }
        o.source = *s;
    }
    auto client = Client::connect(o);
    if (!client) {
        exit_code = out.failure(client.error(), fmt::format("cannot reach {}:{}", g.host, g.port));
        return nullptr;
    }
    return std::move(*client);
}

namespace {

std::optional<Address> address_or_usage(const std::string& text, Output& out, int& exit_code) {
    auto a = parse_address(text);
    if (!a) {
        exit_code = out.usage(fmt::format("bad address '{}': {}", text, a.error().message()));
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
    std::string digits;
    for (const auto& p : parts)
        for (char c : p)
            if (c != ' ' && c != ':') digits += c;
    if (digits.size() % 2 != 0) return std::nullopt;
    std::vector<std::uint8_t> out;
    for (std::size_t i = 0; i < digits.size(); i += 2) {
        unsigned v = 0;
        auto [p, ec] = std::from_chars(digits.data() + i, digits.data() + i + 2, v, 16);
        if (ec != std::errc{} || p != digits.data() + i + 2) return std::nullopt;
        out.push_back(static_cast<std::uint8_t>(v));
    }
    return out;
}

}  // namespace

int Output::usage(const std::string& message) {
    if (json_)
        std::printf(
            "%s\n",
            nlohmann::json{{"error", {{"kind", "usage"}, {"message", message}}}}.dump().c_str());
    std::fprintf(stderr, "fins: %s\n", message.c_str());
    return exit_usage;
}

int Output::failure(std::error_code ec, const std::string& context) {
    const bool end_code = ec.category() == end_code_category();
    if (json_) {
        nlohmann::json e{{"kind", end_code ? "end_code" : "transport"},
                         {"message", ec.message()},
                         {"context", context}};
        if (end_code) {
            e["end_code"] = fmt::format("{:04X}", ec.value());
            const auto* info = find_end_code(static_cast<std::uint16_t>(ec.value()));
            e["name"] = info ? std::string(info->name) : "unknown";
        }
        std::printf("%s\n", nlohmann::json{{"error", e}}.dump().c_str());
    }
    if (end_code)
        std::fprintf(stderr, "fins: %s: the PLC answered %s\n", context.c_str(),
                     ec.message().c_str());
    else
        std::fprintf(stderr, "fins: %s: %s\n", context.c_str(), ec.message().c_str());
    return end_code ? exit_end_code : exit_transport;
}

void Output::print(const nlohmann::json& doc, const std::string& text) {
    if (json_)
        std::printf("%s\n", doc.dump().c_str());
    else
        std::fputs(text.c_str(), stdout);
}

int run_read(const GlobalOptions& g, const ReadArgs& a, Format f, Output& out) {
    int rc = exit_ok;
    auto start = address_or_usage(a.address, out, rc);
    if (!start) return rc;
    const bool bits = f == Format::bits || (start->bit.has_value() && f == Format::uint16);
    if (start->bit && !bits)
        return out.usage(fmt::format("{} names a bit: use --as bits", a.address));
    auto client = open_client(g, out, rc);
    if (!client) return rc;

    nlohmann::json values = nlohmann::json::array();
    std::string text;
    if (bits) {
        auto r = client->read_bits(*start, a.count);
        if (!r) return out.failure(r.error(), fmt::format("read {}", a.address));
        for (std::size_t i = 0; i < r->size(); ++i) {
            values.push_back((*r)[i] ? 1 : 0);
            text +=
                fmt::format("{}  {}\n", format_address(advance(*start, i, true)), (*r)[i] ? 1 : 0);
        }
    } else {
        const std::size_t step = words_per_value(f);
        const std::size_t words = f == Format::string ? a.count : a.count * step;
        auto r = client->read_words(*start, words);
        if (!r) return out.failure(r.error(), fmt::format("read {}", a.address));
        auto printed = print_words(f, *r);
        if (!printed) return out.failure(printed.error(), fmt::format("decode {}", a.address));
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
    const bool bits = f == Format::bits || (start->bit.has_value() && f == Format::uint16);
    if (start->bit && !bits)
        return out.usage(fmt::format("{} names a bit: use --as bits", a.address));
    auto parsed = parse_words(bits ? Format::bits : f, a.values);
    if (auto* e = std::get_if<ParseError>(&parsed)) return out.usage(e->message);
    const auto& words = std::get<std::vector<std::uint16_t>>(parsed);
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
    const char* unit = bits ? "bits" : "words";
    out.print({{"address", format_address(*start)}, {"written", words.size()}, {"unit", unit}},
              fmt::format("wrote {} {} at {}\n", words.size(), unit, format_address(*start)));
    return exit_ok;
}

int run_fill(const GlobalOptions& g, const FillArgs& a, Output& out) {
    int rc = exit_ok;
    auto start = address_or_usage(a.address, out, rc);
    if (!start) return rc;
    auto parsed = parse_words(Format::uint16, {a.value});
    if (auto* e = std::get_if<ParseError>(&parsed)) return out.usage(e->message);
    const auto value = std::get<std::vector<std::uint16_t>>(parsed).at(0);
    auto client = open_client(g, out, rc);
    if (!client) return rc;
    if (auto r = client->fill(*start, a.count, value); !r)
        return out.failure(r.error(), fmt::format("fill {}", a.address));
    out.print({{"address", format_address(*start)}, {"count", a.count}, {"value", value}},
              fmt::format("filled {} words at {} with 0x{:04X}\n", a.count, format_address(*start),
                          value));
    return exit_ok;
}

int run_transfer(const GlobalOptions& g, const TransferArgs& a, Output& out) {
    int rc = exit_ok;
    auto from = address_or_usage(a.from, out, rc);
    if (!from) return rc;
    auto to = address_or_usage(a.to, out, rc);
    if (!to) return rc;
    auto client = open_client(g, out, rc);
    if (!client) return rc;
    if (auto r = client->transfer(*from, *to, a.count); !r)
        return out.failure(r.error(), fmt::format("transfer {} -> {}", a.from, a.to));
    out.print({{"from", format_address(*from)}, {"to", format_address(*to)}, {"count", a.count}},
              fmt::format("copied {} words from {} to {}\n", a.count, format_address(*from),
                          format_address(*to)));
    return exit_ok;
}

int run_read_multi(const GlobalOptions& g, const ReadMultiArgs& a, Output& out) {
    int rc = exit_ok;
    std::vector<Address> addresses;
    for (const auto& text : a.addresses) {
        auto addr = address_or_usage(text, out, rc);
        if (!addr) return rc;
        addresses.push_back(*addr);
    }
    auto client = open_client(g, out, rc);
    if (!client) return rc;
    auto r = client->read_multiple(addresses);
    if (!r) return out.failure(r.error(), "read-multi");
    nlohmann::json items = nlohmann::json::array();
    std::string text;
    for (std::size_t i = 0; i < r->size() && i < addresses.size(); ++i) {
        const auto name = format_address(addresses[i]);
        items.push_back({{"address", name}, {"value", (*r)[i]}});
        text += fmt::format("{}  {}\n", name, (*r)[i]);
    }
    out.print({{"values", items}}, text);
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
                       {"source", fmt::format("{}.{}.{}", r->header.source.network,
                                              r->header.source.node, r->header.source.unit)},
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
    text += fmt::format("\nfrom {}.{}.{} sid {:02X}\ndata ({} bytes): {}\n",
                        r->header.source.network, r->header.source.node, r->header.source.unit,
                        r->header.service_id, r->data.size(), hex_bytes(r->data));
    out.print(doc, text);
    return r->code.ok() ? exit_ok : exit_end_code;
}

}  // namespace fins::cli
