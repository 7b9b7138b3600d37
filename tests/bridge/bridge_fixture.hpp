// Real parts for the bridge tests: a mosquitto broker (bridge_processes.hpp's) plain, with
// TLS from a CA made by openssl, or with a password file from mosquitto_passwd,
// the MQTT Recorder (mqtt_recorder.hpp), and fins-bridge itself. Every wait is bounded.
#pragma once

#include <chrono>
#include <cstdint>
#include <cstdlib>
#include <memory>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "bridge/bridge_processes.hpp"
#include "bridge/mqtt_recorder.hpp"
#include "integration/support/finsd_process.hpp"

namespace fins::bridge::test {

using fins::test::Child;
using fins::test::ScratchDir;

using fins::test::bridge::bridge_path;
using fins::test::bridge::Mosquitto;
using fins::test::bridge::Received;
using fins::test::bridge::Recorder;
inline std::uint16_t free_port() {
    return fins::test::bridge::free_tcp_port();
}
inline bool accepts(std::uint16_t port) {
    return fins::test::bridge::tcp_connectable(port);
}

inline int shell(const std::string& command) {
    return std::system(("(" + command + ") >/dev/null 2>&1").c_str());
}

// TLS material made by openssl in `dir`: ca.crt, server.crt/key for 127.0.0.1.
inline bool make_tls(const ScratchDir& dir) {
    const std::string d = dir.path().string();
    return shell("cd " + d +
                 " && openssl req -x509 -newkey rsa:2048 -nodes -days 1 -subj /CN=finskit-test-ca"
                 " -keyout ca.key -out ca.crt"
                 " && openssl req -newkey rsa:2048 -nodes -subj /CN=127.0.0.1"
                 " -keyout server.key -out server.csr"
                 " && printf 'subjectAltName=IP:127.0.0.1' > san.ext"
                 " && openssl x509 -req -in server.csr -CA ca.crt -CAkey ca.key -CAcreateserial"
                 " -days 1 -extfile san.ext -out server.crt"
                 // mosquitto started as root reads them as the user "mosquitto"
                 " && chmod 0755 . && chmod 0644 ca.crt server.crt server.key") == 0;
}

// fins-bridge with `config` (TOML text) written to `dir`.
class BridgeProcess {
  public:
    BridgeProcess(const ScratchDir& dir, const std::string& config,
                  std::vector<std::string> extra = {}) {
        static int n = 0;
        const auto file = dir.write("bridge-" + std::to_string(n++) + ".toml", config);
        std::vector<std::string> argv{bridge_path, "--config",   file,  "--log-level",
                                      "warn",      "--instance", "test"};
        argv.insert(argv.end(), extra.begin(), extra.end());
        child_ = std::make_unique<Child>(argv, file + ".log");
    }
    // Stops it (SIGKILL after 20 s); its exit status and what it logged.
    struct Stopped {
        int exit_code = -1;  // 128 + signal when killed by one
        std::string err;
    };
    Stopped stop(int signal = SIGTERM) {
        const int status = child_->kill(signal, std::chrono::seconds(20));
        return {status, child_->log()};
    }
    Child& child() { return *child_; }

  private:
    std::unique_ptr<Child> child_;
};

inline std::string mqtt_section(std::uint16_t port, const std::string& extra = "") {
    return "[mqtt]\nhost = \"127.0.0.1\"\nport = " + std::to_string(port) +
           "\ntopic_prefix = \"t\"\nbackoff_min_ms = 50\nbackoff_max_ms = 500\n" + extra;
}

}  // namespace fins::bridge::test
