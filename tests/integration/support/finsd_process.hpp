// finsd started from a test: the one copy for every binary that starts it (test_integration,
// test_web, test_bridge; the library fins_test_finsd). A scratch directory for its files,
// the process with "--port 0" (or a port of the test's, or the config's), its
// "listening <port>" line on stdout, clients and the `fins` CLI to it, and its end: stop()
// says how it ended; a Finsd still running when it goes is stopped with SIGTERM. Every wait
// is bounded (process.hpp).
#pragma once

#include <sys/types.h>

#include <chrono>
#include <csignal>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "fins/client.hpp"
#include "integration/support/process.hpp"

namespace fins::test {

inline const std::string finsd_path = std::string(FINS_BIN_DIR) + "/finsd";
inline const std::string fins_path = std::string(FINS_BIN_DIR) + "/fins";

// A directory of its own under the system's temporary directory, removed at the end.
class ScratchDir {
  public:
    explicit ScratchDir(const std::string& tag);
    ~ScratchDir();
    ScratchDir(const ScratchDir&) = delete;
    ScratchDir& operator=(const ScratchDir&) = delete;

    [[nodiscard]] const std::filesystem::path& path() const { return path_; }
    // Writes `text` to <dir>/<name> and returns the file's path as a string.
    std::string write(const std::string& name, const std::string& text) const;

  private:
    std::filesystem::path path_;
};

// Held by a test whose finsd binds fixed addresses and ports (plant configurations name
// port 9611 on loopback addresses of their own): ctest -j runs each test in its own
// process, and two tests of one file would otherwise bind the same address at once.
// Such tests run one at a time, across processes (an flock, released when the test ends
// or its process dies).
class FixedPorts {
  public:
    FixedPorts();
    ~FixedPorts();
    FixedPorts(const FixedPorts&) = delete;
    FixedPorts& operator=(const FixedPorts&) = delete;

  private:
    int fd_;
};

// How a Finsd runs, besides its arguments.
struct FinsdOptions {
    // "--port N" before the arguments: 0 for a free one; none to leave it to the config.
    std::optional<std::uint16_t> port = 0;
    // "--log-level LEVEL" before the arguments; empty for finsd's default.
    std::string log_level = "warn";
    // Run through /usr/bin/env with these words first ("NAME=value", "-u", "NAME").
    std::vector<std::string> env{};
    // Shell commands run before finsd, in the same process ("ulimit -n 24 && "): sh -c.
    std::string shell{};
    // How long its "listening" line may take.
    std::chrono::milliseconds wait = std::chrono::seconds(20);
};

// finsd with `args` after the options' port and log level. started() is false when it
// exited (or said something else) before listening; result() then holds its exit code and
// stderr.
class Finsd {
  public:
    explicit Finsd(std::vector<std::string> args, FinsdOptions options = {});
    ~Finsd();
    Finsd(const Finsd&) = delete;
    Finsd& operator=(const Finsd&) = delete;

    [[nodiscard]] bool started() const { return started_; }
    // From "listening N": 0 for a finsd without a network port (a serial-only PLC).
    [[nodiscard]] std::uint16_t port() const { return port_; }
    [[nodiscard]] const RunResult& result() const { return result_; }
    [[nodiscard]] pid_t pid() const { return child_->pid(); }
    // The process itself: its stderr (wait_for_stderr), whether it still runs.
    Child& child() { return *child_; }

    // A FINS/UDP (or FINS/TCP) client of it, with a 3 s timeout; null when none connected.
    [[nodiscard]] std::unique_ptr<Client> client(bool tcp = false) const;
    // A client with `options`, their port set to finsd's.
    [[nodiscard]] std::unique_ptr<Client> client(ClientOptions options) const;
    // `fins --port PORT --timeout 2 [--tcp] ARGS...`, run to its end.
    RunResult fins(const std::vector<std::string>& args, bool tcp = false) const;
    // Sends `signal` and waits for the exit (SIGKILL after `timeout`): the exit code (128 + n
    // for a signal n) and what it wrote after what the test read. Once only: a second call
    // returns the first one's result.
    RunResult stop(int signal = SIGTERM,
                   std::chrono::milliseconds timeout = std::chrono::seconds(20));

  private:
    std::unique_ptr<Child> child_;
    bool started_ = false;
    bool stopped_ = false;
    std::uint16_t port_ = 0;
    RunResult result_;
};

// The gtest fixture of a test that talks to one finsd: started before the test (which fails
// when finsd did not start), stopped after it with SIGTERM, which must end it cleanly (exit
// 0). With `control`, finsd has a control channel at socket() in a scratch directory.
class FinsdTest : public ::testing::Test {
  protected:
    explicit FinsdTest(std::vector<std::string> args = {}, bool control = false);
    void SetUp() override;
    void TearDown() override;

    [[nodiscard]] std::string socket() const { return (dir_.path() / "ctl.sock").string(); }
    // `fins --port PORT --timeout 2 [--tcp] ARGS...` against it.
    RunResult fins(const std::vector<std::string>& args, bool tcp = false) const {
        return finsd_.fins(args, tcp);
    }

    ScratchDir dir_{"finsd-test"};
    Finsd finsd_;
};

// `text` as an address; a failed test and Address{} when it is none.
Address addr(const std::string& text);

// `count` words from `text`; empty when the read failed.
std::vector<std::uint16_t> words_of(Client& c, const std::string& text, std::size_t count);

// The end code of a raw request without the flag bits 6/7 (0xFFFF when no answer came).
unsigned end_code(Client& c, CommandCode code, const std::vector<std::uint8_t>& params);

// `finsd ctl --socket SOCKET ARGS...`, run to its end.
RunResult ctl(const std::string& socket, const std::vector<std::string>& args);

// The shipped example scenarios, with a trailing slash.
inline const std::string scenario_examples = std::string(FINS_SOURCE_DIR) + "/examples/scenarios/";

}  // namespace fins::test
