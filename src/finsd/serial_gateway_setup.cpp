// finsd's Serial Gateway ports (see serial_gateway_setup.hpp).
#include "finsd/serial_gateway_setup.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>

#include <fmt/format.h>
#include <spdlog/spdlog.h>

namespace fins::finsd {

namespace {

constexpr std::uint8_t first_bus_unit = 0x10;  // CPU Bus Unit n = 10 + n (frames 1.4)

bool cs_series(const plc::Profile& profile) {
    return profile.model.rfind("CS", 0) == 0;
}

}  // namespace

bool is_gateway_port(const SerialPortConfig& port) noexcept {
    return port.kind != SerialPortConfig::Kind::cpu && port.mode == "gateway";
}

tl::expected<void, std::string> mount_serial_units(const std::vector<SerialPortConfig>& ports,
                                                   plc::Profile& profile) {
    for (const auto& port : ports) {
        if (!is_gateway_port(port)) continue;
        const bool board = port.kind == SerialPortConfig::Kind::board;
        const auto address =
            board ? inner_board_unit : static_cast<std::uint8_t>(first_bus_unit + port.unit_number);
        const std::string model = board                ? "CS1W-SCB41-V1"
                                  : cs_series(profile) ? "CS1W-SCU21-V1"
                                                       : "CJ1W-SCU41-V1";
        if (board && !cs_series(profile))
            return tl::unexpected(
                fmt::format("{}: {}: the Serial Communications Board is a CS-series Inner Board; "
                            "profile {} is not CS-series (use scuN.P)",
                            port.where, port.name, profile.name));
        if (const plc::UnitInfo* there = profile.unit(address)) {
            if (there->model == model) continue;  // the unit's other port
            return tl::unexpected(
                fmt::format("{}: {}: unit address {:02X} is already the {} of profile {}",
                            port.where, port.name, address, there->model, profile.name));
        }
        if (board && profile.loop_control)
            return tl::unexpected(
                fmt::format("{}: {}: the Inner Board slot holds the Loop "
                            "Control Board of profile {}",
                            port.where, port.name, profile.name));
        profile.units.push_back(plc::UnitInfo{address, model, 0, "V1.20"});
    }
    std::sort(profile.units.begin(), profile.units.end(),
              [](const plc::UnitInfo& a, const plc::UnitInfo& b) {
                  return a.unit_address < b.unit_address;
              });
    return {};
}

server::GatewayPortConfig gateway_port_config(const SerialPortConfig& port) {
    server::GatewayPortConfig c;
    c.name = port.name;
    c.unit_address = port.kind == SerialPortConfig::Kind::board
                         ? server::board_port_unit_address(port.port)
                         : server::scu_port_unit_address(port.unit_number, port.port);
    c.line = port.line;
    c.timeout = std::chrono::milliseconds(std::lround(port.timeout_seconds * 1000.0));
    if (port.network) c.network = static_cast<std::uint8_t>(*port.network);
    return c;
}

void open_gateway_ports(asio::io_context& io, const std::vector<SerialPortConfig>& ports,
                        server::SerialPorts& out) {
    for (const auto& port : ports) {
        if (!is_gateway_port(port)) continue;
        auto gateway = std::make_shared<server::SerialGatewayPort>(io, gateway_port_config(port));
        // As on a real unit, a port with nothing behind it still answers: 0205 until its
        // device can be opened (each request retries, at most once a second).
        if (const auto ec = gateway->open())
            spdlog::warn("finsd: serial gateway port {}: {}: {} (answering 0205 until it opens)",
                         port.name, port.line.device, ec.message());
        else
            spdlog::info("finsd: serial gateway port {} on {}, unit address {:02X}", port.name,
                         port.line.device, gateway_port_config(port).unit_address);
        out.add(std::move(gateway));
    }
}

}  // namespace fins::finsd
