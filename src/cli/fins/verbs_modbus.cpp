// `fins modbus`: the coils and registers of a Modbus slave behind a Serial Gateway port,
// through 28 04 CONVERT TO MODBUS-RTU COMMAND or, with --ascii, 28 05 CONVERT TO
// MODBUS-ASCII COMMAND (W342 5-3-47, 5-3-48), so nobody writes 28 04 in hex:
//   fins modbus read coils|discrete|holding|input ADDRESS [COUNT]   01 / 02 / 03 / 04
//   fins modbus write coils ADDRESS VALUE...     05 (one value) / 0F (several)
//   fins modbus write holding ADDRESS VALUE...   06 (one value) / 10 (several)
// --slave 1-247 (0: broadcast, writes only), --gateway scuN.P | board.P | UNIT (the
// port's unit address in hex, W342 5-3-47 tables) or --dest NET.NODE.UNIT. Function codes,
// limits and exception codes: Modbus Application Protocol v1.1b3 6.1-6.12 and 7. The
// slave's own answer is checked (address, function, byte count); an exception response
// (a normal 0000 FINS answer carrying function | 80) exits 4 with the exception's name.
#include <algorithm>
#include <array>
#include <cstdint>
#include <cstdio>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <fmt/core.h>

#include "cli/fins/commands.hpp"
#include "cli/fins/verb_support.hpp"
#include "fins/commands/serial_gateway.hpp"
#include "fins/modbus.hpp"

namespace fins::cli {

namespace {

// Modbus Application Protocol 6.1-6.4, 6.11, 6.12: quantities per request.
constexpr std::size_t max_read_bits = 2000;       // 01, 02
constexpr std::size_t max_read_registers = 125;   // 03, 04
constexpr std::size_t max_write_bits = 1968;      // 0F
constexpr std::size_t max_write_registers = 123;  // 10
constexpr std::uint8_t max_slave = 247;           // W342 5-3-47: 01-F7

struct ModbusArgs {
    std::string action;
    std::string table;
    std::string address;
    std::vector<std::string> rest;
    unsigned slave = 1;
    bool ascii = false;
    std::string gateway;
};

struct Table {
    const char* name;
    std::uint8_t read_function;
    bool bits;
    bool writable;
};
constexpr std::array<Table, 4> tables{{
    {"coils", 0x01, true, true},
    {"discrete", 0x02, true, false},
    {"holding", 0x03, false, true},
    {"input", 0x04, false, false},
}};

// Modbus Application Protocol 7.
const char* exception_name(std::uint8_t code) {
    switch (code) {
        case 0x01:
            return "ILLEGAL FUNCTION";
        case 0x02:
            return "ILLEGAL DATA ADDRESS";
        case 0x03:
            return "ILLEGAL DATA VALUE";
        case 0x04:
            return "SERVER DEVICE FAILURE";
        case 0x05:
            return "ACKNOWLEDGE";
        case 0x06:
            return "SERVER DEVICE BUSY";
        case 0x08:
            return "MEMORY PARITY ERROR";
        case 0x0A:
            return "GATEWAY PATH UNAVAILABLE";
        case 0x0B:
            return "GATEWAY TARGET DEVICE FAILED TO RESPOND";
        default:
            return "unknown exception";
    }
}

// scuN.P, board.P, or the port's unit address in hex as the W342 5-3-47 tables print it
// (85, E4, FD; 0x85 too).
std::optional<std::uint8_t> gateway_unit(const std::string& text) {
    const auto dot = text.find('.');
    if (dot == std::string::npos) {
        const bool prefixed =
            text.size() > 2 && text[0] == '0' && (text[1] == 'x' || text[1] == 'X');
        const auto unit = parse_number(prefixed ? text : "0x" + text, 0xFF);
        if (!unit) return std::nullopt;
        return static_cast<std::uint8_t>(*unit);
    }
    if (dot + 2 != text.size() || (text[dot + 1] != '1' && text[dot + 1] != '2'))
        return std::nullopt;
    const auto port = static_cast<unsigned>(text[dot + 1] - '0');
    const auto head = text.substr(0, dot);
    if (head == "board") return board_port_unit_address(port);
    if (head.size() != 4 || head.rfind("scu", 0) != 0) return std::nullopt;
    const auto n = parse_number("0x" + head.substr(3), 15);
    if (!n) return std::nullopt;
    return scu_port_unit_address(*n, port);
}

struct Exchange {
    std::vector<std::uint8_t> answer;  // slave, function, data; empty after a broadcast
};

// One Modbus request (slave, function, data) through the port; the slave's answer.
Result<Exchange> exchange(Client& client, bool ascii, const std::vector<std::uint8_t>& adu,
                          Output& out) {
    if (!ascii) {
        const Bytes data(adu.data() + 2, adu.size() - 2);
        auto r = send_noting_flags(client, ConvertToModbusRtu{adu[0], adu[1], data}, out);
        if (!r) return Unexpected(r.error());
        return Exchange{std::move(r->data)};
    }
    std::array<std::uint8_t, ConvertToModbusAscii::max_ascii> digits{};
    ByteWriter w(digits);
    modbus::hex_encode(w, adu);
    if (w.overflowed()) return Unexpected(make_error_code(ClientError::request_too_long));
    auto r = send_noting_flags(client, ConvertToModbusAscii{w.written()}, out);
    if (!r) return Unexpected(r.error());
    std::vector<std::uint8_t> binary(r->data.size() / 2);
    const auto n = modbus::hex_decode(r->data, binary);
    if (!n || r->data.size() % 2 != 0)
        return Unexpected(make_error_code(ClientError::malformed_response));
    binary.resize(*n);
    return Exchange{std::move(binary)};
}

// A failure fins words itself: "fins: CONTEXT: MESSAGE" (and a hint) on stderr, the
// error object on stdout under --json, exit 4 (the slave or the port refused).
int refused(Output& out, nlohmann::json error, const std::string& context,
            const std::string& message, const std::string& hint, const char* said = "") {
    error["message"] = message;
    error["context"] = context;
    if (!hint.empty()) error["hint"] = hint;
    if (out.json())
        std::printf("%s\n", nlohmann::json{{"error", error}}
                                .dump(-1, ' ', false, nlohmann::json::error_handler_t::replace)
                                .c_str());
    std::fprintf(stderr, "fins: %s: %s%s\n", context.c_str(), said, message.c_str());
    if (!hint.empty()) std::fprintf(stderr, "fins: %s\n", hint.c_str());
    return exit_end_code;
}

// An exception response (Modbus Application Protocol 7).
int exception(Output& out, const std::string& context, unsigned slave, std::uint8_t code) {
    return refused(
        out, {{"kind", "modbus_exception"}, {"exception", code}, {"name", exception_name(code)}},
        context,
        fmt::format("slave {} answered exception {:02X} ({})", slave, code, exception_name(code)),
        {});
}

// What the FINS end code means for a Modbus request: 0202/0401 name no serial port (the
// generic hint about unit 0 would mislead), 0205 a slave that stayed silent.
int gateway_failure(Output& out, std::error_code ec, const std::string& context,
                    const ModbusArgs& a, const GlobalOptions& target) {
    const bool no_port = ec == make_error_code(EndCode::unit_missing) ||
                         ec == make_error_code(EndCode::undefined_command);
    if (!no_port && ec != make_error_code(EndCode::response_timeout))
        return out.failure(ec, context);
    const auto* info = find_end_code(static_cast<std::uint16_t>(ec.value()));
    const std::string port = a.gateway.empty() ? "--dest " + target.dest : a.gateway;
    return refused(out,
                   {{"kind", "end_code"},
                    {"end_code", fmt::format("{:04X}", ec.value())},
                    {"name", info ? std::string(info->name) : "unknown"}},
                   context, ec.message(),
                   no_port ? fmt::format("no Serial Gateway port at {} (finsd: --serial "
                                         "scuN.P=DEVICE; W342 5-3-47 lists the unit addresses)",
                                         port)
                           : fmt::format("slave {} did not answer within the gateway port's "
                                         "timeout: check --slave, the line settings and the slave",
                                         a.slave),
                   "the PLC answered ");
}

std::vector<std::uint8_t> header(unsigned slave, std::uint8_t function, unsigned address,
                                 unsigned count) {
    return {static_cast<std::uint8_t>(slave),        function,
            static_cast<std::uint8_t>(address >> 8), static_cast<std::uint8_t>(address),
            static_cast<std::uint8_t>(count >> 8),   static_cast<std::uint8_t>(count)};
}

// The request for a write of `values` (0/1 for coils) at `address`.
std::vector<std::uint8_t> write_request(unsigned slave, bool bits, unsigned address,
                                        const std::vector<std::uint16_t>& values) {
    if (values.size() == 1) {
        const std::uint16_t v = bits ? (values[0] ? 0xFF00 : 0x0000) : values[0];
        return header(slave, bits ? 0x05 : 0x06, address, v);
    }
    const auto count = static_cast<unsigned>(values.size());
    auto adu = header(slave, bits ? 0x0F : 0x10, address, count);
    if (bits) {
        adu.push_back(static_cast<std::uint8_t>((count + 7) / 8));
        for (std::size_t i = 0; i < values.size(); i += 8) {
            std::uint8_t packed = 0;
            for (std::size_t b = 0; b < 8 && i + b < values.size(); ++b)
                if (values[i + b]) packed = static_cast<std::uint8_t>(packed | 1U << b);
            adu.push_back(packed);
        }
    } else {
        adu.push_back(static_cast<std::uint8_t>(count * 2));
        for (auto v : values) {
            adu.push_back(static_cast<std::uint8_t>(v >> 8));
            adu.push_back(static_cast<std::uint8_t>(v));
        }
    }
    return adu;
}

int run_modbus(const GlobalOptions& g, const ModbusArgs& a, Output& out) {
    const Table* table = nullptr;
    for (const auto& t : tables)
        if (a.table == t.name) table = &t;
    if (!table)
        return out.usage(
            fmt::format("modbus table '{}': coils, discrete, holding or input", a.table));
    const bool write = a.action == "write";
    if (!write && a.action != "read")
        return out.usage(fmt::format("modbus '{}': read or write", a.action));
    if (write && !table->writable)
        return out.usage(fmt::format(
            "{} are read-only in Modbus: write coils or holding",
            table->name == std::string("input") ? "input registers" : "discrete inputs"));
    const auto address = parse_number(a.address, 0xFFFF);
    if (!address) return out.usage(fmt::format("modbus address '{}': 0-65535", a.address));
    if (a.slave > max_slave) return out.usage(fmt::format("--slave {}: 0-247", a.slave));
    if (a.slave == 0 && !write)
        return out.usage("--slave 0 is a broadcast, which no slave answers: reads need 1-247");

    // The port: --gateway sets the unit of --dest (or of the derived node).
    GlobalOptions target = g;
    if (!a.gateway.empty()) {
        const auto unit = gateway_unit(a.gateway);
        if (!unit)
            return out.usage(fmt::format(
                "--gateway '{}': scuN.P (N 0-F, P 1 or 2), board.P or a unit address in hex (85)",
                a.gateway));
        auto dest =
            g.dest.empty() ? std::optional<NodeAddress>{NodeAddress{}} : parse_node_address(g.dest);
        if (!dest) return out.usage(fmt::format("--dest '{}' is not NET.NODE.UNIT", g.dest));
        target.dest = fmt::format("{}.{}.0x{:02X}", dest->network, dest->node, *unit);
    } else if (auto dest = parse_node_address(g.dest); !dest || dest->unit == 0) {
        return out.usage(
            "28 04 goes to a serial port's unit address: add --gateway scu1.2 (or board.1), or "
            "--dest NET.NODE.UNIT with the port's unit (80 + 4N + P - 1, hex)");
    }

    std::vector<std::uint16_t> values;
    std::size_t count = 1;
    if (write) {
        if (a.rest.empty()) return out.usage("modbus write: give the values to write");
        for (const auto& text : a.rest) {
            const auto v = parse_number(text, table->bits ? 1 : 0xFFFF);
            if (!v)
                return out.usage(fmt::format(
                    "value '{}': {}", text,
                    table->bits ? "a coil is 0 or 1" : "a register is 0-65535 or 0x0000-0xFFFF"));
            values.push_back(static_cast<std::uint16_t>(*v));
        }
        count = values.size();
        const auto max = table->bits ? max_write_bits : max_write_registers;
        if (count > max)
            return out.usage(
                fmt::format("{} values: one Modbus write takes at most {}", count, max));
    } else if (a.rest.size() > 1) {
        return out.usage("modbus read: ADDRESS [COUNT]");
    } else if (a.rest.size() == 1) {
        const auto max = table->bits ? max_read_bits : max_read_registers;
        const auto n = parse_number(a.rest[0], static_cast<std::uint32_t>(max));
        if (!n || *n == 0)
            return out.usage(fmt::format("count '{}': 1-{} per Modbus read", a.rest[0], max));
        count = *n;
    }
    if (*address + count > 0x10000)
        return out.usage(fmt::format("{} from {} run past 65535", count, *address));

    int rc = exit_ok;
    auto client = open_client(target, out, rc);
    if (!client) return rc;
    const auto context = fmt::format("modbus {} {} {}", a.action, table->name, *address);
    const auto request =
        write ? write_request(a.slave, table->bits, *address, values)
              : header(a.slave, table->read_function, *address, static_cast<unsigned>(count));
    auto r = exchange(*client, a.ascii, request, out);
    if (!r) return gateway_failure(out, r.error(), context, a, target);
    const auto& answer = r->answer;
    const auto malformed = [&] {
        return out.failure(make_error_code(ClientError::malformed_response), context);
    };
    nlohmann::json doc{{"slave", a.slave}, {"table", table->name}, {"start", *address}};
    if (a.slave == 0) {
        doc["written"] = count;
        out.print(doc, fmt::format("sent {} to every slave (broadcast: no answer)\n",
                                   plural(count, table->bits ? "coil" : "register")));
        return exit_ok;
    }
    if (answer.size() < 2 || answer[0] != a.slave) return malformed();
    if (answer[1] == (request[1] | modbus::exception_bit) && answer.size() == 3)
        return exception(out, context, a.slave, answer[2]);
    if (answer[1] != request[1]) return malformed();
    if (write) {
        // 05/06 echo the request; 0F/10 answer address and quantity.
        const std::size_t echoed = values.size() == 1 ? request.size() : 6;
        if (answer.size() != echoed || !std::equal(answer.begin(), answer.end(), request.begin()))
            return malformed();
        doc["written"] = count;
        out.print(doc, fmt::format("wrote {} at {} {} of slave {}\n",
                                   plural(count, table->bits ? "coil" : "register"), table->name,
                                   *address, a.slave));
        return exit_ok;
    }
    const std::size_t bytes = table->bits ? (count + 7) / 8 : count * 2;
    if (answer.size() != 3 + bytes || answer[2] != bytes) return malformed();
    nlohmann::json read = nlohmann::json::array();
    std::string text;
    for (std::size_t i = 0; i < count; ++i) {
        const unsigned v = table->bits ? (unsigned{answer[3 + i / 8]} >> (i % 8)) & 1U
                                       : unsigned{answer[3 + 2 * i]} << 8 | answer[4 + 2 * i];
        read.push_back(v);
        text += fmt::format("{} {}  {}\n", table->name, *address + i, v);
    }
    doc["values"] = read;
    out.print(doc, text);
    return exit_ok;
}

}  // namespace

void add_modbus_verbs(CLI::App& app, const GlobalOptions& g, int& exit_code) {
    auto a = std::make_shared<ModbusArgs>();
    auto* c = verb(app, "modbus",
                   "Read/write a Modbus slave behind a Serial Gateway port (28 04 / 28 05)", g,
                   exit_code, a, &run_modbus);
    c->add_option("action", a->action, "read or write")->required();
    c->add_option("table", a->table, "coils, discrete, holding or input")->required();
    c->add_option("address", a->address, "First coil or register, 0-65535")->required();
    c->add_option("rest", a->rest, "read: COUNT (default 1); write: the values");
    c->add_option("--slave", a->slave, "Modbus slave address, 1-247 (0: broadcast write)")
        ->capture_default_str();
    c->add_flag("--ascii", a->ascii, "Modbus-ASCII (28 05) instead of Modbus-RTU (28 04)");
    c->add_option("--gateway", a->gateway,
                  "The Serial Gateway port: scuN.P, board.P or its unit address in hex (85, E4)");
}

}  // namespace fins::cli
