// Child processes, loopback ports and the mosquitto broker for every bridge test
// (bridge_fixture.hpp, the cluster and Sparkplug tests in cluster/processes.hpp,
// bench/bridge_failover.cpp): one copy. A child's stdout and stderr go to a log file, so a chatty
// child never blocks on a full pipe; it dies with the test (PR_SET_PDEATHSIG) and is killed by its
// destructor. Every wait is bounded.
#pragma once

#include <arpa/inet.h>
#include <fcntl.h>
#include <netinet/in.h>
#include <signal.h>
#include <sys/prctl.h>
#include <sys/socket.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <memory>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "integration/free_port.hpp"

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

// A child process whose stdout and stderr go to `log`.
class Proc {
  public:
    Proc(const std::vector<std::string>& argv, const std::filesystem::path& log) : log_(log) {
        const pid_t parent = ::getpid();
        pid_ = ::fork();
        if (pid_ == 0) {
            if (::prctl(PR_SET_PDEATHSIG, SIGKILL) != 0 || ::getppid() != parent) ::_exit(127);
            const int fd = ::open(log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
            if (fd >= 0) {
                ::dup2(fd, 1);
                ::dup2(fd, 2);
                ::close(fd);
            }
            std::vector<char*> args;
            for (const auto& a : argv)
                args.push_back(const_cast<char*>(a.c_str()));
            args.push_back(nullptr);
            ::execv(args[0], args.data());
            ::_exit(127);
        }
    }
    ~Proc() { kill(SIGKILL); }
    Proc(const Proc&) = delete;
    Proc& operator=(const Proc&) = delete;

    // Sends `sig` and reaps the child (bounded: SIGKILL after `timeout`). The exit status.
    int kill(int sig, std::chrono::milliseconds timeout = 10s) {
        if (pid_ <= 0 || reaped_) return status_;
        ::kill(pid_, sig);
        const auto deadline = std::chrono::steady_clock::now() + timeout;
        int st = 0;
        while (::waitpid(pid_, &st, WNOHANG) == 0) {
            if (std::chrono::steady_clock::now() > deadline) {
                ::kill(pid_, SIGKILL);
                ::waitpid(pid_, &st, 0);
                break;
            }
            std::this_thread::sleep_for(10ms);
        }
        reaped_ = true;
        status_ = WIFEXITED(st) ? WEXITSTATUS(st) : 128 + WTERMSIG(st);
        return status_;
    }
    [[nodiscard]] pid_t pid() const { return pid_; }
    bool running() {
        if (pid_ <= 0 || reaped_) return false;
        int st = 0;
        if (::waitpid(pid_, &st, WNOHANG) == pid_) {
            reaped_ = true;
            status_ = WIFEXITED(st) ? WEXITSTATUS(st) : 128 + WTERMSIG(st);
            return false;
        }
        return true;
    }
    std::string log() const {
        std::ifstream in(log_);
        std::stringstream s;
        s << in.rdbuf();
        return s.str();
    }

  private:
    std::filesystem::path log_;
    pid_t pid_ = -1;
    bool reaped_ = false;
    int status_ = -1;
};

// mosquitto on a free 127.0.0.1 port with no persistence (up to 5 ports tried, in case
// another test took one meanwhile). `extra`: more lines for the
// listener (TLS files, password_file ...); anonymous clients are allowed unless it names a
// password_file. Its config and log are mosquitto-PORT.conf(.log) in `dir`.
class Mosquitto {
  public:
    explicit Mosquitto(const std::filesystem::path& dir, const std::string& extra = "") {
        const auto exe = mosquitto_path();
        if (exe.empty()) return;
        const bool anonymous = extra.find("password_file") == std::string::npos;
        for (int attempt = 0; attempt < 5 && !started_; ++attempt) {
            port_ = free_tcp_port();
            const auto conf = dir / ("mosquitto-" + std::to_string(port_) + ".conf");
            std::ofstream(conf) << "per_listener_settings true\npersistence false\n"
                                << "listener " << port_ << " 127.0.0.1\n"
                                << "allow_anonymous " << (anonymous ? "true" : "false") << "\n"
                                << extra;
            proc_ = std::make_unique<Proc>(std::vector<std::string>{exe, "-c", conf.string()},
                                           conf.string() + ".log");
            const auto deadline = std::chrono::steady_clock::now() + 10s;
            while (std::chrono::steady_clock::now() < deadline && proc_->running()) {
                if (tcp_connectable(port_)) {
                    started_ = true;
                    break;
                }
                std::this_thread::sleep_for(20ms);
            }
        }
    }
    [[nodiscard]] bool started() const { return started_; }
    [[nodiscard]] std::uint16_t port() const { return port_; }

  private:
    std::unique_ptr<Proc> proc_;
    std::uint16_t port_ = 0;
    bool started_ = false;
};

}  // namespace fins::test::bridge
