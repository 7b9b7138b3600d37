// Real parts for the Sparkplug and multi-instance tests: a UDP relay in front of finsd that
// counts the requests of each sender (which instance polls which PLC). Child processes, ports
// and the mosquitto broker are bridge_processes.hpp's; the MQTT Recorder mqtt_recorder.hpp's.
// Every wait is bounded.
#pragma once

#include <arpa/inet.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <atomic>
#include <cstdint>
#include <map>
#include <mutex>
#include <thread>
#include <vector>

#include "bridge/bridge_processes.hpp"
#include "bridge/mqtt_recorder.hpp"

namespace fins::test::bridge {

using namespace std::chrono_literals;

// UDP relays in front of one finsd: relay i listens on its own loopback port (a PLC of the
// bridge's config) and forwards to finsd's port, each sender through its own upstream socket
// so answers go back to it. It counts the requests of every sender per relay: two senders
// on one relay in a stable period means two instances polled that PLC.
class CountingRelay {
  public:
    CountingRelay(std::size_t relays, std::uint16_t finsd_port) : finsd_port_(finsd_port) {
        for (std::size_t i = 0; i < relays; ++i) {
            const int fd = udp_socket(0);
            listen_.push_back(fd);
            sockaddr_in a{};
            socklen_t len = sizeof a;
            ::getsockname(fd, reinterpret_cast<sockaddr*>(&a), &len);
            ports_.push_back(ntohs(a.sin_port));
        }
        thread_ = std::thread([this] { loop(); });
    }
    ~CountingRelay() {
        stop_ = true;
        thread_.join();
        for (int fd : listen_)
            ::close(fd);
        for (auto& [k, fd] : upstream_)
            ::close(fd);
    }
    CountingRelay(const CountingRelay&) = delete;
    CountingRelay& operator=(const CountingRelay&) = delete;

    [[nodiscard]] std::uint16_t port(std::size_t relay) const { return ports_[relay]; }

    // Requests per sender ("port") seen by relay i since the last reset.
    std::map<std::uint16_t, std::uint64_t> senders(std::size_t relay) const {
        std::lock_guard lock(mu_);
        std::map<std::uint16_t, std::uint64_t> out;
        for (const auto& [key, n] : counts_)
            if (key.first == relay) out[key.second] = n;
        return out;
    }
    // MEMORY AREA WRITE (01 02) frames relay i passed on, since the start.
    std::uint64_t writes(std::size_t relay) const {
        std::lock_guard lock(mu_);
        const auto it = writes_.find(relay);
        return it == writes_.end() ? 0 : it->second;
    }
    void reset() {
        std::lock_guard lock(mu_);
        counts_.clear();
    }

  private:
    static int udp_socket(std::uint16_t port) {
        const int fd = ::socket(AF_INET, SOCK_DGRAM | SOCK_NONBLOCK, 0);
        sockaddr_in a{};
        a.sin_family = AF_INET;
        a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
        a.sin_port = htons(port);
        ::bind(fd, reinterpret_cast<sockaddr*>(&a), sizeof a);
        return fd;
    }

    void loop() {
        char buf[4096];
        while (!stop_) {
            std::vector<pollfd> fds;
            for (int fd : listen_)
                fds.push_back({fd, POLLIN, 0});
            std::vector<std::pair<std::size_t, sockaddr_in>> owners;  // upstream fd order
            std::vector<int> ups;
            {
                for (const auto& [key, fd] : upstream_) {
                    fds.push_back({fd, POLLIN, 0});
                    ups.push_back(fd);
                    owners.push_back({key.first, client_[key]});
                }
            }
            if (::poll(fds.data(), fds.size(), 50) <= 0) continue;
            for (std::size_t i = 0; i < listen_.size(); ++i) {
                if (!(fds[i].revents & POLLIN)) continue;
                sockaddr_in from{};
                socklen_t len = sizeof from;
                const auto n = ::recvfrom(listen_[i], buf, sizeof buf, 0,
                                          reinterpret_cast<sockaddr*>(&from), &len);
                if (n <= 0) continue;
                const std::pair<std::size_t, std::uint16_t> key{i, ntohs(from.sin_port)};
                auto it = upstream_.find(key);
                if (it == upstream_.end()) {
                    it = upstream_.emplace(key, udp_socket(0)).first;
                    client_[key] = from;
                }
                {
                    std::lock_guard lock(mu_);
                    ++counts_[key];
                    // FINS header (10 bytes) then the command code: 01 02 MEMORY AREA WRITE.
                    if (n >= 12 && buf[10] == 0x01 && buf[11] == 0x02) ++writes_[i];
                }
                sockaddr_in to{};
                to.sin_family = AF_INET;
                to.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
                to.sin_port = htons(finsd_port_);
                ::sendto(it->second, buf, static_cast<std::size_t>(n), 0,
                         reinterpret_cast<sockaddr*>(&to), sizeof to);
            }
            for (std::size_t j = 0; j < ups.size(); ++j) {
                if (!(fds[listen_.size() + j].revents & POLLIN)) continue;
                const auto n = ::recv(ups[j], buf, sizeof buf, 0);
                if (n <= 0) continue;
                const auto& [relay, client] = owners[j];
                ::sendto(listen_[relay], buf, static_cast<std::size_t>(n), 0,
                         reinterpret_cast<const sockaddr*>(&client), sizeof client);
            }
        }
    }

    std::uint16_t finsd_port_;
    std::vector<int> listen_;
    std::vector<std::uint16_t> ports_;
    std::map<std::pair<std::size_t, std::uint16_t>, int> upstream_;
    std::map<std::pair<std::size_t, std::uint16_t>, sockaddr_in> client_;
    mutable std::mutex mu_;
    std::map<std::pair<std::size_t, std::uint16_t>, std::uint64_t> counts_;
    std::map<std::size_t, std::uint64_t> writes_;
    std::atomic<bool> stop_{false};
    std::thread thread_;
};

}  // namespace fins::test::bridge
