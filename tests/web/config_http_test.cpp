// finsd's [http] table and --http flags (finsd/config_http.hpp): what is accepted,
// and the refusals that keep a controllable server off the network without a token.
#include <gtest/gtest.h>

#include <string>

#include "finsd/config.hpp"
#include "finsd/config_http.hpp"

namespace fins::test {
namespace {

using namespace fins::finsd;

TEST(ConfigHttp, ParsesListenAddresses) {
    EXPECT_EQ(*parse_http_listen("127.0.0.1:8080"),
              (std::pair<std::string, std::uint16_t>{"127.0.0.1", 8080}));
    EXPECT_EQ(*parse_http_listen("[::1]:0"), (std::pair<std::string, std::uint16_t>{"::1", 0}));
    EXPECT_EQ(parse_http_listen("0.0.0.0:80")->first, "0.0.0.0");
    for (const char* bad : {"", "8080", "localhost:8080", "127.0.0.1:", "127.0.0.1:70000",
                            "127.0.0.1:x", "[::1]8080", "1.2.3:80"})
        EXPECT_FALSE(parse_http_listen(bad)) << bad;
    EXPECT_TRUE(loopback_address("127.0.0.1"));
    EXPECT_TRUE(loopback_address("127.3.2.1"));
    EXPECT_TRUE(loopback_address("::1"));
    EXPECT_FALSE(loopback_address("0.0.0.0"));
    EXPECT_FALSE(loopback_address("192.168.1.5"));
}

TEST(ConfigHttp, LoadsTheTable) {
    Settings s;
    auto r = load_config_text(R"(
[http]
listen = "127.0.0.1:8081"
control = true
token_file = "/tmp/token"
allowed_hosts = ["plc-sim.lan"]
allowed_origins = ["https://scada.lan", "http://10.0.0.5:8080"]
max_connections = 10
)",
                              "test.toml", s);
    ASSERT_TRUE(r) << r.error();
    EXPECT_EQ(s.http.listen, "127.0.0.1:8081");
    EXPECT_TRUE(s.http.control);
    EXPECT_EQ(s.http.token_file, "/tmp/token");
    EXPECT_EQ(s.http.allowed_hosts, std::vector<std::string>{"plc-sim.lan"});
    EXPECT_EQ(s.http.allowed_origins,
              (std::vector<std::string>{"https://scada.lan", "http://10.0.0.5:8080"}));
    EXPECT_EQ(s.http.max_connections, 10u);
}

TEST(ConfigHttp, RefusesBadKeysNamingThem) {
    for (const char* text :
         {"[http]\nlisten = 8080\n", "[http]\nlisten = \"x:1\"\n", "[http]\ncontrol = 1\n",
          "[http]\nmax_connections = 0\n", "[http]\nallowed_hosts = \"a\"\n", "[http]\nport = 1\n",
          "[http]\nallowed_origins = [\"scada.lan\"]\n",
          "[http]\nallowed_origins = [\"https://scada.lan/page\"]\n", "http = 1\n"}) {
        Settings s;
        auto r = load_config_text(text, "test.toml", s);
        ASSERT_FALSE(r) << text;
        EXPECT_NE(r.error().find("http"), std::string::npos) << r.error();
    }
}

TEST(ConfigHttp, ControlBeyondLoopbackNeedsAToken) {
    HttpSettings h;
    EXPECT_TRUE(check_http(h));
    h.control = true;
    EXPECT_FALSE(check_http(h));  // --http-control without --http
    h.listen = "127.0.0.1:8080";
    EXPECT_TRUE(check_http(h));
    h.listen = "0.0.0.0:8080";
    auto r = check_http(h);
    ASSERT_FALSE(r);
    EXPECT_NE(r.error().find("--http-token-file"), std::string::npos);
    h.token_file = "/etc/finsd/token";
    EXPECT_TRUE(check_http(h));
    h.control = false;
    h.token_file.reset();
    EXPECT_TRUE(check_http(h));  // read-only beyond loopback is allowed
}

}  // namespace
}  // namespace fins::test
