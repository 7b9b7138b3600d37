// finsd's start of the HTTP front (finsd/web_setup.hpp): the token file is read and
// required by POSTs, a missing one stops finsd with exit 2, no --http starts nothing.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "finsd/web_setup.hpp"
#include "web_server.hpp"

namespace fins::test {
namespace {

TEST(WebSetup, ReadsTheTokenFileAndServes) {
    asio::io_context io{1};
    plc::Plc plc;
    server::ControlTarget t;
    t.plc = &plc;
    finsd::HttpSettings http;
    EXPECT_EQ(finsd::start_web(io, http, {t}, {}).server, nullptr);  // no --http

    http.listen = "127.0.0.1:0";
    http.control = true;
    http.token_file =
        std::filesystem::temp_directory_path() / ("finskit-token-" + std::to_string(::getpid()));
    auto missing = finsd::start_web(io, http, {t}, {});
    EXPECT_EQ(missing.exit_code, 2);
    EXPECT_NE(missing.error.find("--http-token-file"), std::string::npos);

    std::ofstream(*http.token_file) << "  s3cret \n";
    auto started = finsd::start_web(io, http, {t}, {});
    ASSERT_NE(started.server, nullptr) << started.error;
    std::thread runner([&] { io.run(); });
    {
        HttpClient c(started.server->port());
        EXPECT_EQ(c.request(http::verb::post, "/api/write", R"({"address":"D1","values":[1]})")
                      .result_int(),
                  403u);
        EXPECT_EQ(c.request(http::verb::post, "/api/write", R"({"address":"D1","values":[1]})",
                            {{"Authorization", "Bearer s3cret"}})
                      .result_int(),
                  200u);
        auto metrics = c.request(http::verb::get, "/metrics");
        EXPECT_NE(metrics.body().find("fins_tcp_connections{state=\"established\"} 0"),
                  std::string::npos);
    }
    asio::post(io, [&] {
        started.server->stop();
        io.stop();
    });
    runner.join();
    std::filesystem::remove(*http.token_file);
    EXPECT_EQ(plc.memory().words(Region::dm)[1], 1);
}

}  // namespace
}  // namespace fins::test
