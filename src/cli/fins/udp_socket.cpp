#include "cli/fins/udp_socket.hpp"

#include <boost/asio/ip/address_v4.hpp>

namespace fins::cli {

namespace asio = boost::asio;
using asio::ip::udp;

namespace {

std::error_code portable(const boost::system::error_code& ec) {
    // Windows reports an ICMP port unreachable on a UDP socket as WSAECONNRESET, Linux as
    // ECONNREFUSED: one meaning, one code.
    if (ec == asio::error::connection_reset)
        return std::make_error_code(std::errc::connection_refused);
    return ec;
}

}  // namespace

std::error_code UdpSocket::open_v4() {
    boost::system::error_code ec;
    socket_.open(udp::v4(), ec);
    if (!ec) socket_.non_blocking(true, ec);
    return ec;
}

std::error_code UdpSocket::connect(const std::string& host, std::uint16_t port) {
    boost::system::error_code ec;
    udp::resolver resolver(io_);
    const auto found = resolver.resolve(host, std::to_string(port), ec);
    if (ec || found.empty()) return std::make_error_code(std::errc::host_unreachable);
    const Endpoint to = found.begin()->endpoint();
    socket_.open(to.protocol(), ec);
    if (!ec) socket_.non_blocking(true, ec);
    if (!ec) socket_.connect(to, ec);
    return ec;
}

std::optional<std::uint32_t> UdpSocket::local_v4() const {
    boost::system::error_code ec;
    const auto local = socket_.local_endpoint(ec);
    if (ec || !local.address().is_v4()) return std::nullopt;
    return local.address().to_v4().to_uint();
}

std::error_code UdpSocket::send(std::span<const std::uint8_t> datagram) {
    boost::system::error_code ec;
    const auto n = socket_.send(asio::buffer(datagram.data(), datagram.size()), 0, ec);
    if (!ec && n != datagram.size()) return std::make_error_code(std::errc::message_size);
    return portable(ec);
}

std::error_code UdpSocket::send_to(std::uint32_t ipv4, std::uint16_t port,
                                   std::span<const std::uint8_t> datagram) {
    boost::system::error_code ec;
    const Endpoint to(asio::ip::address_v4(ipv4), port);
    const auto n = socket_.send_to(asio::buffer(datagram.data(), datagram.size()), to, 0, ec);
    if (!ec && n != datagram.size()) return std::make_error_code(std::errc::message_size);
    return portable(ec);
}

bool UdpSocket::wait_readable(std::chrono::milliseconds left) {
    bool ready = false;
    socket_.async_wait(udp::socket::wait_read, [&ready](const boost::system::error_code& ec) {
        if (!ec) ready = true;
    });
    io_.restart();
    io_.run_for(std::max(left, std::chrono::milliseconds(0)));
    if (!ready) {
        // The wait's handler still has to run (aborted) before the next wait.
        boost::system::error_code ignored;
        socket_.cancel(ignored);
        io_.restart();
        io_.run();
    }
    return ready;
}

Result<std::size_t> UdpSocket::receive(std::span<std::uint8_t> into, std::chrono::milliseconds left,
                                       Endpoint* from) {
    if (!wait_readable(left)) return std::size_t{0};
    boost::system::error_code ec;
    Endpoint sender;
    const auto n = socket_.receive_from(asio::buffer(into.data(), into.size()), sender, 0, ec);
    if (ec == asio::error::would_block) return std::size_t{0};
    if (ec) return Unexpected(portable(ec));
    if (from != nullptr) *from = sender;
    return n;
}

std::optional<std::size_t> UdpSocket::try_receive(std::span<std::uint8_t> into, Endpoint& from) {
    boost::system::error_code ec;
    const auto n = socket_.receive_from(asio::buffer(into.data(), into.size()), from, 0, ec);
    if (ec) return std::nullopt;
    return n;
}

}  // namespace fins::cli
