// GET /metrics: the Prometheus text format that Debian's promtool accepts, and counters
// that move with what happened (a FINS request through the dispatcher, HTTP answers).
#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>

#include "fins/frame.hpp"
#include "server/metrics/metrics.hpp"
#include "web_server.hpp"

namespace fins::test {
namespace {

// Runs `promtool check metrics` on `text`; its exit code and output.
std::pair<int, std::string> promtool(const std::string& text) {
    const auto dir = std::filesystem::temp_directory_path();
    const auto in = dir / ("fins_metrics_" + std::to_string(::getpid()) + ".txt");
    std::ofstream(in) << text;
    const std::string command = "promtool check metrics < " + in.string() + " 2>&1";
    FILE* p = ::popen(command.c_str(), "r");
    std::string out;
    char buffer[512];
    while (p != nullptr && std::fgets(buffer, sizeof buffer, p) != nullptr)
        out += buffer;
    const int rc = p != nullptr ? ::pclose(p) : -1;
    std::filesystem::remove(in);
    return {rc, out};
}

TEST(Metrics, CountersMoveWithEvents) {
    using namespace server::metrics;
    Metrics m;
    m.requests.add(0x0101u << 16 | 0x0000);
    m.requests.add(0x0101u << 16 | 0x0000);
    m.requests.add(0x0102u << 16 | 0x2101);
    EXPECT_EQ(m.requests.value(0x0101u << 16), 2u);
    EXPECT_EQ(m.requests.value(0x0102u << 16 | 0x2101), 1u);
    m.request_duration.observe(std::chrono::microseconds(3));
    m.request_duration.observe(std::chrono::seconds(1));
    const auto text = expose(m);
    EXPECT_NE(text.find("fins_requests_total{command=\"0101\",end_code=\"0000\"} 2\n"),
              std::string::npos);
    EXPECT_NE(text.find("fins_request_duration_seconds_bucket{le=\"5e-06\"} 1\n"),
              std::string::npos)
        << text;
    EXPECT_NE(text.find("fins_request_duration_seconds_bucket{le=\"+Inf\"} 2\n"),
              std::string::npos);
    // More distinct keys than the table holds: counted, not lost.
    KeyedCounter k;
    for (std::uint32_t i = 0; i < KeyedCounter::slots + 10; ++i)
        k.add(i);
    EXPECT_EQ(k.overflow(), 10u);
}

TEST(Metrics, ServedTextPassesPromtool) {
    if (std::system("command -v promtool >/dev/null 2>&1") != 0)
        GTEST_SKIP() << "promtool is not installed (Debian package prometheus)";
    WebServer s;
    HttpClient c(s.port());
    EXPECT_EQ(c.request(http::verb::get, "/nope").result_int(), 404u);
    server::metrics::start_request();
    server::metrics::note_request(CommandCode{0x01, 0x01}, EndCode::normal_completion);
    server::metrics::note_relay_error(EndCode::no_routing_tables);
    server::metrics::note_instruction(2, 0x0205);
    auto r = c.request(http::verb::get, "/metrics");
    EXPECT_EQ(r.result_int(), 200u);
    EXPECT_EQ(r[http::field::content_type], "text/plain; version=0.0.4; charset=utf-8");
    EXPECT_NE(r.body().find("fins_http_requests_total{code=\"404\"}"), std::string::npos);
    EXPECT_NE(r.body().find("fins_instructions_total{instruction=\"sendcmd\",completion=\"0205\"}"),
              std::string::npos);
    const auto [rc, out] = promtool(r.body());
    EXPECT_EQ(rc, 0) << out << "\n" << r.body();
}

}  // namespace
}  // namespace fins::test
