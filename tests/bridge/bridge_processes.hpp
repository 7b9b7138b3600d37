// Programs, loopback ports and the mosquitto broker for every bridge test (bridge_fixture.hpp,
// the cluster and Sparkplug tests in cluster/processes.hpp, bench/bridge_failover.cpp,
// bench/bridge_load.cpp): one copy. Children are integration/support/process.hpp's Child, with
// their stdout and stderr in a log file, so a chatty child never blocks on a full pipe. Every wait
// is bounded.
#pragma once

#include <arpa/inet.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <chrono>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include "integration/support/free_port.hpp"
#include "integration/support/process.hpp"

namespace fins::test::bridge {

using namespace std::chrono_literals;

inline const std::string bridge_path = std::string(FINS_BIN_DIR) + "/fins-bridge";
inline const std::string finsd_exe = std::string(FINS_BIN_DIR) + "/finsd";

inline bool have_program(const std::string& path) {
    return ::access(path.c_str(), X_OK) == 0;
}
inline std::string mosquitto_path() {
    for (const char* p : {"/usr/sbin/mosquitto", "/usr/bin/mosquitto"})
        if (have_program(p)) return p;
    return {};
}

using fins::test::Child;
using fins::test::free_tcp_port;

inline bool tcp_connectable(std::uint16_t port) {
    const int fd = ::socket(AF_INET, SOCK_STREAM, 0);
    sockaddr_in a{};
    a.sin_family = AF_INET;
    a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    a.sin_port = htons(port);
    const bool ok = ::connect(fd, reinterpret_cast<sockaddr*>(&a), sizeof a) == 0;
    ::close(fd);
    return ok;
}

// mosquitto on a free 127.0.0.1 port (up to 5 ports tried, in case another test took one
// meanwhile), without persistence unless `persistent`: then its sessions and queued
// messages are saved in `dir` on a clean stop and restored by restart(). `extra`: more lines
// for the listener (TLS files, password_file ...); anonymous clients are allowed unless it
// names a password_file. Its config and log are mosquitto-PORT.conf(.log) in `dir`.
class Mosquitto {
  public:
    explicit Mosquitto(const std::filesystem::path& dir, const std::string& extra = "",
                       bool persistent = false) {
        exe_ = mosquitto_path();
        if (exe_.empty()) return;
        const bool anonymous = extra.find("password_file") == std::string::npos;
        for (int attempt = 0; attempt < 5 && !started_; ++attempt) {
            port_ = free_tcp_port();
            conf_ = dir / ("mosquitto-" + std::to_string(port_) + ".conf");
            std::ofstream out(conf_);
            out << "per_listener_settings true\n";
            if (persistent) {
                // mosquitto started as root runs as the user "mosquitto": it writes its
                // database into this (scratch) directory.
                std::error_code ec;
                std::filesystem::permissions(dir, std::filesystem::perms::all, ec);
                out << "persistence true\npersistence_location " << dir.string() << "/\n"
                    << "persistence_file mosquitto-" << port_ << ".db\n";
            } else {
                out << "persistence false\n";
            }
            out << "listener " << port_ << " 127.0.0.1\n"
                << "allow_anonymous " << (anonymous ? "true" : "false") << "\n"
                << extra;
            out.close();
            run();
        }
    }
    [[nodiscard]] bool started() const { return started_; }
    [[nodiscard]] std::uint16_t port() const { return port_; }
    [[nodiscard]] pid_t pid() const { return proc_ ? proc_->pid() : -1; }

    // Stops it with SIGTERM (a persistent broker saves its state then), waiting at most 20 s.
    void stop() {
        if (proc_) proc_->kill(SIGTERM, std::chrono::seconds(20));
        started_ = false;
    }
    // Starts it again on the same port; true once it accepts connections.
    bool restart() {
        stop();
        run();
        return started_;
    }

  private:
    void run() {
        proc_ = std::make_unique<Child>(std::vector<std::string>{exe_, "-c", conf_.string()},
                                        conf_.string() + ".log");
        const auto deadline = std::chrono::steady_clock::now() + 10s;
        while (std::chrono::steady_clock::now() < deadline && proc_->running()) {
            if (tcp_connectable(port_)) {
                started_ = true;
                break;
            }
            std::this_thread::sleep_for(20ms);
        }
    }

    std::string exe_;
    std::filesystem::path conf_;
    std::unique_ptr<Child> proc_;
    std::uint16_t port_ = 0;
    bool started_ = false;
};

}  // namespace fins::test::bridge
