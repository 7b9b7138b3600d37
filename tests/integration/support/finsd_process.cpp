#include "integration/support/finsd_process.hpp"

#include <fcntl.h>
#include <sys/file.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <fstream>

#include <gtest/gtest.h>

namespace fins::test {

namespace {

// `word` for sh: in single quotes, each quote in it closed, escaped and reopened.
std::string quoted(const std::string& word) {
    std::string out = "'";
    for (const char c : word)
        out += c == '\'' ? std::string("'\\''") : std::string(1, c);
    return out + "'";
}

std::vector<std::string> finsd_argv(std::vector<std::string> args, const FinsdOptions& o) {
    std::vector<std::string> argv{finsd_path};
    if (o.port) argv.insert(argv.end(), {"--port", std::to_string(*o.port)});
    if (!o.log_level.empty()) argv.insert(argv.end(), {"--log-level", o.log_level});
    argv.insert(argv.end(), args.begin(), args.end());
    if (!o.shell.empty()) {
        std::string line = o.shell + "exec";
        for (const auto& word : argv)
            line += " " + quoted(word);
        argv = {"/bin/sh", "-c", line};
    }
    if (!o.env.empty()) {
        std::vector<std::string> env{"/usr/bin/env"};
        env.insert(env.end(), o.env.begin(), o.env.end());
        argv.insert(argv.begin(), env.begin(), env.end());
    }
    return argv;
}

}  // namespace

ScratchDir::ScratchDir(const std::string& tag) {
    static std::atomic<int> n{0};
    path_ = std::filesystem::temp_directory_path() /
            ("finskit-" + tag + "-" + std::to_string(::getpid()) + "-" + std::to_string(n++));
    std::filesystem::remove_all(path_);
    std::filesystem::create_directories(path_);
}

ScratchDir::~ScratchDir() {
    std::error_code ec;
    std::filesystem::remove_all(path_, ec);
}

std::string ScratchDir::write(const std::string& name, const std::string& text) const {
    std::ofstream(path_ / name, std::ios::binary) << text;
    return (path_ / name).string();
}

FixedPorts::FixedPorts()
    : fd_(::open("/tmp/finskit-tests-fixed-ports.lock", O_CREAT | O_RDWR | O_CLOEXEC, 0666)) {
    if (fd_ >= 0)
        while (::flock(fd_, LOCK_EX) != 0 && errno == EINTR) {
        }
}

FixedPorts::~FixedPorts() {
    if (fd_ >= 0) ::close(fd_);
}

Finsd::Finsd(std::vector<std::string> args, FinsdOptions options)
    : child_(std::make_unique<Child>(finsd_argv(std::move(args), options))) {
    const std::string line = child_->read_line(options.wait);
    if (line.rfind("listening ", 0) == 0) {
        started_ = true;  // "listening 0": no network port (a serial-only PLC)
        port_ = static_cast<std::uint16_t>(std::stoul(line.substr(10)));
    } else {
        result_ = child_->wait(std::chrono::seconds(20));
        stopped_ = true;
    }
}

Finsd::~Finsd() {
    stop();
}

std::unique_ptr<Client> Finsd::client(bool tcp) const {
    ClientOptions o;
    o.protocol = tcp ? ClientOptions::Protocol::tcp : ClientOptions::Protocol::udp;
    o.timeout = std::chrono::milliseconds(3000);
    return client(o);
}

std::unique_ptr<Client> Finsd::client(ClientOptions options) const {
    options.port = port_;
    auto c = Client::connect(options);
    EXPECT_TRUE(c.has_value()) << (c ? "" : c.error().message());
    return c ? std::move(*c) : nullptr;
}

RunResult Finsd::fins(const std::vector<std::string>& args, bool tcp) const {
    std::vector<std::string> argv{fins_path, "--port", std::to_string(port_), "--timeout", "2"};
    if (tcp) argv.emplace_back("--tcp");
    argv.insert(argv.end(), args.begin(), args.end());
    return run(argv);
}

RunResult Finsd::stop(int signal, std::chrono::milliseconds timeout) {
    if (stopped_) return result_;
    stopped_ = true;
    child_->terminate(signal);
    result_ = child_->wait(timeout);
    return result_;
}

FinsdTest::FinsdTest(std::vector<std::string> args, bool control)
    : finsd_([&] {
          if (control) args.insert(args.end(), {"--control", socket()});
          return std::move(args);
      }()) {}

void FinsdTest::SetUp() {
    ASSERT_TRUE(finsd_.started()) << finsd_.result().err;
}

void FinsdTest::TearDown() {
    const auto r = finsd_.stop();
    EXPECT_EQ(r.exit_code, 0) << r.err;  // SIGTERM is a clean shutdown
}

Address addr(const std::string& text) {
    auto a = parse_address(text);
    EXPECT_TRUE(a.has_value()) << text;
    return a.value_or(Address{});
}

std::vector<std::uint16_t> words_of(Client& c, const std::string& text, std::size_t count) {
    auto r = c.read_words(addr(text), count);
    EXPECT_TRUE(r.has_value()) << text << ": " << (r ? "" : r.error().message());
    return r.value_or(std::vector<std::uint16_t>{});
}

unsigned end_code(Client& c, CommandCode code, const std::vector<std::uint8_t>& params) {
    auto r = c.send_raw(code, params);
    return r ? static_cast<unsigned>(r->code.end_code()) : 0xFFFFU;
}

RunResult ctl(const std::string& socket, const std::vector<std::string>& args) {
    std::vector<std::string> argv{finsd_path, "ctl", "--socket", socket};
    argv.insert(argv.end(), args.begin(), args.end());
    return run(argv);
}

}  // namespace fins::test
