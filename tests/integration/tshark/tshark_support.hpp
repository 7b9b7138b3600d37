// Shared by the tshark conformance tests: a live capture of one port on `lo` and the
// dissector's fields for every FINS frame in it.
//
// Capturing needs root or the wireshark group (as CI has); a test checks ready() and
// skips with the reason otherwise. The kernel hands packets to dumpcap in blocks and
// dumpcap drops an unfinished block when stopped, so read_until() re-reads the growing
// file (bounded) until the test's last exchange is in it, and only then stops and reads
// the finished file.
#pragma once

#include <signal.h>
#include <unistd.h>

#include <cstdint>
#include <filesystem>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "integration/support/process.hpp"

namespace fins::test::tshark {

inline const std::string binary = "/usr/bin/tshark";
// Expert-info severity as tshark prints it: epan/proto.h PI_WARN.
inline constexpr long severity_warning = 0x00600000;

inline std::vector<std::string> split(const std::string& s, char sep) {
    std::vector<std::string> out(1);
    for (char c : s) {
        if (c == sep)
            out.emplace_back();
        else
            out.back() += c;
    }
    return out;
}

// Every FINS frame of `capture`, with `port` decoded as FINS over UDP and TCP: one line
// per frame, the `fields` separated by '|'.
inline RunResult decode(const std::string& capture, const std::string& port,
                        const std::vector<std::string>& fields) {
    std::vector<std::string> argv{binary,
                                  "-r",
                                  capture,
                                  "-d",
                                  "udp.port==" + port + ",omron",
                                  "-d",
                                  "tcp.port==" + port + ",omron",
                                  "-Y",
                                  "omron",
                                  "-T",
                                  "fields",
                                  "-E",
                                  "separator=|"};
    for (const auto& f : fields) {
        argv.push_back("-e");
        argv.push_back(f);
    }
    return run(argv);
}

// Lines of a decode whose field `column` equals `value` (e.g. the end-marker command).
inline int count_rows(const RunResult& decoded, std::size_t column, const std::string& value) {
    int n = 0;
    std::size_t start = 0;
    while (start < decoded.out.size()) {
        auto end = decoded.out.find('\n', start);
        if (end == std::string::npos) end = decoded.out.size();
        const auto fields = split(decoded.out.substr(start, end - start), '|');
        if (column < fields.size() && fields[column] == value) ++n;
        start = end + 1;
    }
    return n;
}

class Capture {
  public:
    // Starts capturing `port` into a file under a fresh temporary directory.
    Capture(std::uint16_t port, const std::string& tag)
        : port_(std::to_string(port)),
          dir_(std::filesystem::temp_directory_path() /
               ("fins-tshark-" + tag + "-" + std::to_string(::getpid()))) {
        if (!std::filesystem::exists(binary)) return;
        std::filesystem::create_directories(dir_);
        file_ = (dir_ / "capture.pcapng").string();
        dump_ = std::make_unique<Child>(
            std::vector<std::string>{binary, "-i", "lo", "-f", "port " + port_, "-w", file_});
        ready_ = dump_->wait_for_stderr("Capture started");
    }
    ~Capture() {
        stop();
        std::error_code ignored;
        std::filesystem::remove_all(dir_, ignored);
    }
    Capture(const Capture&) = delete;
    Capture& operator=(const Capture&) = delete;

    // False when tshark is missing or may not capture here (the test skips).
    [[nodiscard]] bool ready() const { return ready_; }
    [[nodiscard]] const std::string& port() const { return port_; }

    // Decodes the growing capture until `done` says the test's traffic is all in it (at
    // most 60 reads), then stops capturing and decodes the finished file once more: that
    // last decode is the one returned. A read of the file while dumpcap writes it may end
    // in a block cut short (tshark then exits 2: "cut short in the middle of a packet"),
    // however complete the test's frames before it are; the stopped file has no such end.
    RunResult read_until(const std::vector<std::string>& fields,
                         const std::function<bool(const RunResult&)>& done) {
        for (int attempt = 0; attempt < 60; ++attempt)
            if (done(decode(file_, port_, fields))) break;
        stop();
        return decode(file_, port_, fields);
    }

  private:
    void stop() {
        if (!dump_) return;
        dump_->terminate(SIGINT);
        dump_->wait();
        dump_.reset();
    }

    std::string port_;
    std::filesystem::path dir_;
    std::string file_;
    std::unique_ptr<Child> dump_;
    bool ready_ = false;
};

}  // namespace fins::test::tshark
