// GET /metrics: the Prometheus text format that Debian's promtool accepts, and counters
// that move with what happened (a FINS request through the dispatcher, HTTP answers).
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <new>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include <fmt/core.h>

#include "fins/command_table.hpp"
#include "fins/frame.hpp"
#include "plc/plc.hpp"
#include "server/control/control_dispatch.hpp"
#include "server/dispatch/dispatcher.hpp"
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

// The series of fins_requests_total in `text`.
std::vector<std::string> request_series(const std::string& text) {
    std::vector<std::string> out;
    std::istringstream in(text);
    for (std::string line; std::getline(in, line);)
        if (line.rfind("fins_requests_total{", 0) == 0) out.push_back(line.substr(0, line.find('}')));
    return out;
}

TEST(Metrics, CommandCodesFinsdDoesNotKnowShareOneSeries) {
    plc::Plc plc;
    server::Dispatcher dispatcher(plc, NodeAddress{0, 1, 0});
    const auto before = request_series(expose(server::metrics::process_metrics()));
    // A client sending random command codes: each answered 0401, none a series of its own.
    std::mt19937 random(25);
    std::array<std::uint8_t, max_frame_size> frame{};
    std::array<std::uint8_t, max_frame_size> out{};
    Header h;
    h.destination = {0, 1, 0};
    h.source = {0, 2, 0};
    std::size_t unknown = 0;
    for (int i = 0; i < 3000; ++i) {
        const CommandCode c{static_cast<std::uint8_t>(random()), static_cast<std::uint8_t>(random())};
        if (find_command(c) != nullptr) continue;
        h.service_id = static_cast<std::uint8_t>(i);
        const auto n = encode_request(h, c, {}, frame);
        ASSERT_TRUE(n);
        ASSERT_GT(dispatcher.handle(Bytes{frame.data(), *n}, out, {}), 0u);
        ++unknown;
    }
    ASSERT_GT(unknown, 2000u);
    const auto after = request_series(expose(server::metrics::process_metrics()));
    EXPECT_LE(after.size(), before.size() + 1);
    EXPECT_NE(std::find(after.begin(), after.end(),
                        "fins_requests_total{command=\"other\",end_code=\"0401\""),
              after.end());
    // A command of the table keeps its own series.
    const auto n = encode_request(h, CommandCode{0x01, 0x01}, Bytes{}, frame);
    ASSERT_TRUE(n);
    dispatcher.handle(Bytes{frame.data(), *n}, out, {});
    const auto known = request_series(expose(server::metrics::process_metrics()));
    EXPECT_NE(std::find_if(known.begin(), known.end(),
                           [](const std::string& s) {
                               return s.rfind("fins_requests_total{command=\"0101\"", 0) == 0;
                           }),
              known.end());
}

void throw_bad_alloc(const nlohmann::json&) {
    throw std::bad_alloc();
}

TEST(Metrics, ControlFailuresOverHttpAreAnsweredCountedAndExported) {
    web::WebOptions o;
    o.control = true;
    WebServer s(o);
    HttpClient c(s.port());
    const auto before = server::metrics::process_metrics().control_failures.load();
    server::set_control_fault_for_tests(throw_bad_alloc);
    auto r = c.request(http::verb::post, "/api/control", R"({"cmd":"mode","mode":"program"})");
    server::set_control_fault_for_tests(nullptr);
    EXPECT_EQ(r.result_int(), 500u);
    EXPECT_EQ(body_json(r)["error"], "internal error: std::bad_alloc (out of memory)") << r.body();
    // The server goes on (a 5xx answer closes its connection: http_session.cpp): the next
    // request on a new connection.
    HttpClient c2(s.port());
    r = c2.request(http::verb::post, "/api/control", R"({"cmd":"mode","mode":"program"})");
    EXPECT_EQ(r.result_int(), 200u) << r.body();
    r = c2.request(http::verb::get, "/metrics");
    EXPECT_NE(r.body().find(fmt::format("fins_control_failures_total {}\n", before + 1)),
              std::string::npos)
        << r.body();
    EXPECT_NE(r.body().find("fins_request_failures_total "), std::string::npos);
    if (std::system("command -v promtool >/dev/null 2>&1") == 0) {
        const auto [rc, out] = promtool(r.body());
        EXPECT_EQ(rc, 0) << out << "\n" << r.body();
    }
}

}  // namespace
}  // namespace fins::test
