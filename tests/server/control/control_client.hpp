// A blocking client of the control channel (Unix socket or loopback TCP) with bounded
// waits, and scratch socket paths (tests/server/control).
#pragma once

#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>
#include <sys/un.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <string>

#include <nlohmann/json.hpp>

namespace fins::test {

inline std::filesystem::path socket_path() {
    static std::atomic<int> counter{0};
    return std::filesystem::temp_directory_path() /
           ("fins-ctl-" + std::to_string(::getpid()) + "-" + std::to_string(counter++) + ".sock");
}

// A blocking client with bounded waits.
class ControlClient {
  public:
    explicit ControlClient(const std::filesystem::path& path) {
        fd_ = ::socket(AF_UNIX, SOCK_STREAM | SOCK_CLOEXEC, 0);
        sockaddr_un a{};
        a.sun_family = AF_UNIX;
        std::strncpy(a.sun_path, path.c_str(), sizeof a.sun_path - 1);
        connected_ = ::connect(fd_, reinterpret_cast<const sockaddr*>(&a), sizeof a) == 0;
    }
    // The loopback channel's (control_channel_file.hpp): 127.0.0.1:port over TCP.
    explicit ControlClient(std::uint16_t port) {
        fd_ = ::socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC, 0);
        sockaddr_in a{};
        a.sin_family = AF_INET;
        a.sin_port = htons(port);
        a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
        connected_ = ::connect(fd_, reinterpret_cast<const sockaddr*>(&a), sizeof a) == 0;
    }
    ~ControlClient() { ::close(fd_); }
    [[nodiscard]] bool connected() const { return connected_; }

    void send_raw(const std::string& bytes) {
        std::size_t sent = 0;
        while (sent < bytes.size()) {
            const auto n = ::send(fd_, bytes.data() + sent, bytes.size() - sent, MSG_NOSIGNAL);
            if (n <= 0) return;
            sent += static_cast<std::size_t>(n);
        }
    }
    // The next answer line ("" on timeout or EOF).
    std::string line() {
        const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(10);
        while (std::chrono::steady_clock::now() < deadline) {
            if (const auto end = pending_.find('\n'); end != std::string::npos) {
                std::string l = pending_.substr(0, end);
                pending_.erase(0, end + 1);
                return l;
            }
            pollfd p{fd_, POLLIN, 0};
            if (::poll(&p, 1, 100) <= 0) continue;
            char buf[4096];
            const auto n = ::recv(fd_, buf, sizeof buf, 0);
            if (n <= 0) {
                eof_ = true;
                return "";
            }
            pending_.append(buf, static_cast<std::size_t>(n));
        }
        return "";
    }
    nlohmann::json request(const std::string& text) {
        send_raw(text + "\n");
        return nlohmann::json::parse(line(), nullptr, false);
    }
    // True once the server closed the connection (bounded wait).
    bool closed() {
        line();
        return eof_;
    }

  private:
    int fd_ = -1;
    bool connected_ = false;
    bool eof_ = false;
    std::string pending_;
};

}  // namespace fins::test
