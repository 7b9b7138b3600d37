// Running build/bin/finsd from a test: a scratch directory, a config file in it, the
// process with "--port 0", its "listening <port>" line, and clients to it. Every wait
// is bounded (process.hpp).
#pragma once

#include <fcntl.h>
#include <sys/file.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <filesystem>
#include <fstream>
#include <memory>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "fins/client.hpp"
#include "integration/support/process.hpp"

namespace fins::test {

inline const std::string finsd_path = std::string(FINS_BIN_DIR) + "/finsd";

class ScratchDir {
  public:
    explicit ScratchDir(const std::string& tag) {
        static std::atomic<int> n{0};
        path_ = std::filesystem::temp_directory_path() /
                ("finskit-" + tag + "-" + std::to_string(::getpid()) + "-" + std::to_string(n++));
        std::filesystem::remove_all(path_);
        std::filesystem::create_directories(path_);
    }
    ~ScratchDir() {
        std::error_code ec;
        std::filesystem::remove_all(path_, ec);
    }
    ScratchDir(const ScratchDir&) = delete;
    ScratchDir& operator=(const ScratchDir&) = delete;

    [[nodiscard]] const std::filesystem::path& path() const { return path_; }
    // Writes `text` to <dir>/<name> and returns the file's path as a string.
    std::string write(const std::string& name, const std::string& text) const {
        std::ofstream(path_ / name, std::ios::binary) << text;
        return (path_ / name).string();
    }

  private:
    std::filesystem::path path_;
};

// finsd with `args` after "--port 0 --log-level warn". started() is false when it exited
// before listening; result() then holds its exit code and stderr.
// Held by a test whose finsd binds fixed addresses and ports (plant configurations name
// port 9611 on loopback addresses of their own): ctest -j runs each test in its own
// process, and two tests of one file would otherwise bind the same address at once.
// Such tests run one at a time, across processes (an flock, released when the test ends
// or its process dies).
class FixedPorts {
  public:
    FixedPorts()
        : fd_(::open("/tmp/finskit-tests-fixed-ports.lock", O_CREAT | O_RDWR | O_CLOEXEC, 0666)) {
        if (fd_ >= 0)
            while (::flock(fd_, LOCK_EX) != 0 && errno == EINTR) {
            }
    }
    ~FixedPorts() {
        if (fd_ >= 0) ::close(fd_);
    }
    FixedPorts(const FixedPorts&) = delete;
    FixedPorts& operator=(const FixedPorts&) = delete;

  private:
    int fd_;
};

class Finsd {
  public:
    explicit Finsd(std::vector<std::string> args) {
        std::vector<std::string> argv{finsd_path, "--port", "0", "--log-level", "warn"};
        argv.insert(argv.end(), args.begin(), args.end());
        child_ = std::make_unique<Child>(argv);
        const std::string line = child_->read_line(std::chrono::seconds(20));
        if (line.rfind("listening ", 0) == 0) {
            started_ = true;  // "listening 0": no network port (a serial-only PLC)
            port_ = static_cast<std::uint16_t>(std::stoul(line.substr(10)));
        } else {
            result_ = child_->wait(std::chrono::seconds(20));
        }
    }
    [[nodiscard]] bool started() const { return started_; }
    [[nodiscard]] std::uint16_t port() const { return port_; }
    [[nodiscard]] const RunResult& result() const { return result_; }
    [[nodiscard]] pid_t pid() const { return child_->pid(); }

    std::unique_ptr<Client> client(bool tcp = false) const {
        ClientOptions o;
        o.port = port_;
        o.protocol = tcp ? ClientOptions::Protocol::tcp : ClientOptions::Protocol::udp;
        o.timeout = std::chrono::milliseconds(3000);
        auto c = Client::connect(o);
        EXPECT_TRUE(c.has_value()) << (c ? "" : c.error().message());
        return c ? std::move(*c) : nullptr;
    }
    // Sends `signal` and waits for the exit: the exit code (128 + n for a signal).
    RunResult stop(int signal = SIGTERM) {
        child_->terminate(signal);
        result_ = child_->wait(std::chrono::seconds(20));
        return result_;
    }

  private:
    std::unique_ptr<Child> child_;
    bool started_ = false;
    std::uint16_t port_ = 0;
    RunResult result_;
};

inline Address addr(const std::string& text) {
    auto a = parse_address(text);
    EXPECT_TRUE(a.has_value()) << text;
    return a.value_or(Address{});
}

// `count` words from `text`; empty when the read failed.
inline std::vector<std::uint16_t> words_of(Client& c, const std::string& text, std::size_t count) {
    auto r = c.read_words(addr(text), count);
    EXPECT_TRUE(r.has_value()) << text << ": " << (r ? "" : r.error().message());
    return r.value_or(std::vector<std::uint16_t>{});
}

// The end code of a raw request without the flag bits 6/7 (0xFFFF when no answer came).
inline unsigned end_code(Client& c, CommandCode code, const std::vector<std::uint8_t>& params) {
    auto r = c.send_raw(code, params);
    return r ? static_cast<unsigned>(r->code.end_code()) : 0xFFFFU;
}

// `finsd ctl --socket SOCKET ARGS...`, run to its end.
inline RunResult ctl(const std::string& socket, const std::vector<std::string>& args) {
    std::vector<std::string> argv{finsd_path, "ctl", "--socket", socket};
    argv.insert(argv.end(), args.begin(), args.end());
    return run(argv);
}

// The shipped example scenarios, with a trailing slash.
inline const std::string scenario_examples = std::string(FINS_SOURCE_DIR) + "/examples/scenarios/";

}  // namespace fins::test
