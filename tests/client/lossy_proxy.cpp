#include "client/lossy_proxy.hpp"

#include <memory>

#include <boost/asio/executor_work_guard.hpp>
#include <boost/asio/steady_timer.hpp>

#include "transport/asio.hpp"

namespace fins::test {

using asio::ip::udp;

LossyUdpProxy::LossyUdpProxy(std::uint16_t server_port, Faults faults)
    : front_(io_, udp::endpoint{asio::ip::make_address("127.0.0.1"), 0}),
      back_(io_, udp::endpoint{asio::ip::make_address("127.0.0.1"), 0}),
      faults_(faults),
      rng_(faults.seed) {
    back_.connect(udp::endpoint{asio::ip::make_address("127.0.0.1"), server_port});
    // Room for every datagram of a burst: the proxy must lose only what it decides to.
    front_.set_option(asio::socket_base::receive_buffer_size(1 << 22));
    back_.set_option(asio::socket_base::receive_buffer_size(1 << 22));
    port_ = front_.local_endpoint().port();
    receive_front();
    receive_back();
    thread_ = std::thread([this] {
        auto guard = asio::make_work_guard(io_);
        io_.run();
    });
}

LossyUdpProxy::~LossyUdpProxy() {
    io_.stop();
    thread_.join();
}

LossyUdpProxy::Counts LossyUdpProxy::counts() {
    std::lock_guard lock(mutex_);
    return counts_;
}

void LossyUdpProxy::receive_front() {
    front_.async_receive_from(
        asio::buffer(front_buffer_), from_, [this](boost::system::error_code ec, std::size_t n) {
            if (ec == asio::error::operation_aborted) return;
            if (!ec) {
                client_ = from_;
                have_client_ = true;
                pass({front_buffer_.begin(), front_buffer_.begin() + static_cast<long>(n)}, true);
            }
            receive_front();
        });
}

void LossyUdpProxy::receive_back() {
    back_.async_receive(
        asio::buffer(back_buffer_), [this](boost::system::error_code ec, std::size_t n) {
            if (ec == asio::error::operation_aborted) return;
            if (!ec && have_client_)
                pass({back_buffer_.begin(), back_buffer_.begin() + static_cast<long>(n)}, false);
            receive_back();
        });
}

void LossyUdpProxy::emit(const std::vector<std::uint8_t>& datagram, bool to_server) {
    boost::system::error_code ignored;
    if (to_server)
        back_.send(asio::buffer(datagram), 0, ignored);
    else
        front_.send_to(asio::buffer(datagram), client_, 0, ignored);
}

void LossyUdpProxy::pass(std::vector<std::uint8_t> datagram, bool to_server) {
    std::uniform_real_distribution<double> unit(0.0, 1.0);
    const double u = unit(rng_);
    std::lock_guard lock(mutex_);
    if (u < faults_.drop) {
        ++counts_.dropped;
        return;
    }
    if (u < faults_.drop + faults_.duplicate) {
        ++counts_.duplicated;
        emit(datagram, to_server);
        emit(datagram, to_server);
        return;
    }
    if (u < faults_.drop + faults_.duplicate + faults_.delay) {
        ++counts_.delayed;
        std::uniform_int_distribution<std::chrono::milliseconds::rep> ms(1,
                                                                         faults_.max_delay.count());
        auto timer = std::make_shared<asio::steady_timer>(io_, std::chrono::milliseconds(ms(rng_)));
        auto held = std::make_shared<std::vector<std::uint8_t>>(std::move(datagram));
        timer->async_wait([this, timer, held, to_server](boost::system::error_code ec) {
            if (!ec) emit(*held, to_server);
        });
        return;
    }
    ++counts_.forwarded;
    emit(datagram, to_server);
}

}  // namespace fins::test
