// Shared by fuzz_dispatch and fuzz_session: the routes a frame can take besides the local
// CPU Unit (issue 18: the fuzzers never reached the Host Link relay). CPU Unit A is node
// 1.x and 2.1, CPU Unit B is 2.5 (ports added by each target); A's routing tables relay
// network 3 through 2.5; A's Serial Gateway has a CompoWay/F-style port (unit 80) and a
// Host Link port for network 5 (unit 81), both on a device that does not exist, so every
// job ends 0205 without a line.
#pragma once

#include <memory>

#include <boost/asio/io_context.hpp>

#include "plc/plc.hpp"
#include "plc/routing_tables.hpp"
#include "server/serial/serial_gateway_port.hpp"
#include "server/serial/serial_ports.hpp"
#include "transport/asio.hpp"

namespace fins_fuzz {

// A's routing tables: networks 1 (its unit 0) and 2 (its unit 1) local, 3 through 2.5.
inline void write_routing_tables(fins::plc::Plc& a) {
    fins::plc::RoutingTables tables;
    tables.local[0] = {1, 0};
    tables.local[1] = {2, 1};
    tables.local_count = 2;
    tables.relay[0] = {3, 2, 5};
    tables.relay_count = 1;
    fins::plc::encode_routing_tables(tables, a.parameters().words(fins::plc::routing_table_area));
}

// A gateway port (unit 80) and a Host Link port for FINS network 5 (unit 81).
inline void add_gateway_ports(asio::io_context& io, fins::server::SerialPorts& ports) {
    fins::server::GatewayPortConfig gateway;
    gateway.name = "scu0.1";
    gateway.unit_address = 0x80;
    gateway.line.device = "/nonexistent/fuzz-gateway";
    ports.add(std::make_shared<fins::server::SerialGatewayPort>(io, gateway));
    fins::server::GatewayPortConfig host_link = gateway;
    host_link.name = "scu0.2";
    host_link.unit_address = 0x81;
    host_link.network = 5;
    ports.add(std::make_shared<fins::server::SerialGatewayPort>(io, host_link));
}

}  // namespace fins_fuzz
