// finsd's serial ports at run time: a Host Link slave session (server/serial/serial_session.hpp)
// for each port in mode "hostlink" (the CPU Unit's port, or a unit's port set to Host
// Link), attached to the server's dispatcher.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include <boost/asio/io_context.hpp>
#include <tl/expected.hpp>

#include "finsd/config_serial.hpp"
#include "server/dispatch/dispatcher.hpp"
#include "server/serial/serial_session.hpp"
#include "transport/asio.hpp"

namespace fins::finsd {

struct SerialPorts {
    std::vector<std::shared_ptr<server::SerialSession>> host_link;
    void stop() {
        for (auto& s : host_link)
            s->close();
    }
};

// Starts every port; a device that cannot be opened yet is logged and retried (finsd
// keeps serving Ethernet). Error: a port whose mode this build does not serve.
tl::expected<void, std::string> start_serial_ports(asio::io_context& io,
                                                   server::Dispatcher& dispatcher,
                                                   const std::vector<SerialPortConfig>& ports,
                                                   SerialPorts& out);

}  // namespace fins::finsd
