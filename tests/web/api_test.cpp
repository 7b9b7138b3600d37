// The HTTP API as a plain function (web/api.hpp): every route, the security rules and
// bad input, against a real virtual CPU Unit and with no sockets.
#include <gtest/gtest.h>

#include <string>

#include <nlohmann/json.hpp>

#include "plc/plc.hpp"
#include "web/api.hpp"
#include "web/assets.hpp"

namespace fins::test {
namespace {

using Json = nlohmann::json;

class Api : public ::testing::Test {
  protected:
    Api() {
        server::ControlTarget t;
        t.plc = &plc_;
        t.addresses = {{0, 1}};
        context_.targets.push_back(t);
    }
    web::HttpAnswer call(std::string_view method, std::string_view target,
                         std::string_view body = {}) {
        web::HttpAnswer answer;
        int calls = 0;
        web::handle_request(context_, method, target, body, [&](web::HttpAnswer a) {
            answer = std::move(a);
            ++calls;
        });
        EXPECT_EQ(calls, 1);
        return answer;
    }
    Json json(const web::HttpAnswer& a) {
        EXPECT_EQ(a.content_type, "application/json");
        return Json::parse(a.body);
    }

    plc::Plc plc_;
    web::WebContext context_;
};

TEST_F(Api, ReadsWordsWithTheCliFormats) {
    plc_.memory().words(Region::dm)[100] = 1;
    plc_.memory().words(Region::dm)[101] = 2;
    plc_.memory().words(Region::dm)[102] = 3;
    auto a = call("GET", "/api/read?address=D100&count=3&as=uint16");
    EXPECT_EQ(a.status, 200u);
    EXPECT_EQ(json(a), Json::parse(R"({"address":"D100","as":"uint16","values":[1,2,3]})"));
    // int32: the least significant word first (fins/values.hpp), as `fins read --as int32`.
    EXPECT_EQ(json(call("GET", "/api/read?address=D100&count=1&as=int32"))["values"],
              Json::array({131073}));
    EXPECT_EQ(json(call("GET", "/api/read?address=D100&as=hex"))["values"],
              Json::array({"0x0001"}));
    // The default is one uint16.
    EXPECT_EQ(json(call("GET", "/api/read?address=D102"))["values"], Json::array({3}));
}

TEST_F(Api, ReadsBitsFlagsAndText) {
    plc_.memory().words(Region::cio)[10] = 1u << 13;
    EXPECT_EQ(json(call("GET", "/api/read?address=CIO10.12&count=3")),
              Json::parse(R"({"address":"CIO10.12","as":"bits","values":[0,1,0]})"));
    EXPECT_EQ(json(call("GET", "/api/read?address=CIO10.13&as=bool"))["values"], Json::array({1}));
    // T5 with bits: the completion flag.
    plc_.memory().set_completion_flag(5, true);
    EXPECT_EQ(json(call("GET", "/api/read?address=T5&as=bits"))["values"], Json::array({1}));
    plc_.memory().words(Region::dm)[0] = 0x4142;  // "AB"
    auto text = json(call("GET", "/api/read?address=D0&count=2&as=ascii"));
    EXPECT_EQ(text["as"], "string");
    EXPECT_EQ(text["values"], Json::array({"AB"}));
}

TEST_F(Api, RefusesBadReadsWith400AndAReason) {
    for (const char* target :
         {"/api/read", "/api/read?address=", "/api/read?address=Q5",
          "/api/read?address=D100&as=word", "/api/read?address=D100&count=0",
          "/api/read?address=D100&count=x", "/api/read?address=D100&count=5000",
          "/api/read?address=D32767&count=2", "/api/read?address=D100.3&as=int16",
          "/api/read?address=D100&as=bits", "/api/read?address=IR0&as=float"}) {
        auto a = call("GET", target);
        EXPECT_EQ(a.status, 400u) << target;
        EXPECT_FALSE(json(a)["error"].get<std::string>().empty()) << target;
    }
    // Not BCD: the word is named.
    plc_.memory().words(Region::dm)[7] = 0x00AB;
    auto a = call("GET", "/api/read?address=D7&as=bcd");
    EXPECT_EQ(a.status, 400u);
    EXPECT_NE(json(a)["error"].get<std::string>().find("0x00AB"), std::string::npos);
}

TEST_F(Api, WritesOnlyWithControlOn) {
    auto refused = call("POST", "/api/write", R"({"address":"D100","values":[7]})");
    EXPECT_EQ(refused.status, 403u);
    EXPECT_EQ(plc_.memory().words(Region::dm)[100], 0);  // nothing reached the PLC
    auto control = call("POST", "/api/control", R"({"cmd":"mode","mode":"program"})");
    EXPECT_EQ(control.status, 403u);
    EXPECT_EQ(plc_.mode(), plc::OperatingMode::run);

    context_.options.control = true;
    auto a =
        call("POST", "/api/write", R"({"address":"D100","values":[7,"0x12AB",-1],"as":"int16"})");
    EXPECT_EQ(a.status, 200u) << a.body;
    EXPECT_EQ(json(a), Json::parse(R"({"ok":true,"written":3})"));
    EXPECT_EQ(plc_.memory().words(Region::dm)[100], 7);
    EXPECT_EQ(plc_.memory().words(Region::dm)[101], 0x12AB);
    EXPECT_EQ(plc_.memory().words(Region::dm)[102], 0xFFFF);
    EXPECT_EQ(
        call("POST", "/api/write", R"({"address":"D200","values":[1.5],"as":"float"})").status,
        200u);
    EXPECT_EQ(plc_.memory().words(Region::dm)[201], 0x3FC0);
    EXPECT_EQ(call("POST", "/api/write", R"({"address":"CIO10.2","values":[true,1]})").status,
              200u);
    EXPECT_EQ(plc_.memory().words(Region::cio)[10], 0b1100);
    EXPECT_EQ(
        call("POST", "/api/write", R"({"address":"D300","values":"HELLO","as":"ascii"})").status,
        200u);
    EXPECT_EQ(plc_.memory().words(Region::dm)[300], 0x4845);
}

TEST_F(Api, RefusesBadWritesWithNothingWritten) {
    context_.options.control = true;
    for (const char* body :
         {"", "[]", "{", R"({"values":[1]})", R"({"address":"D100"})",
          R"({"address":"D100","values":[]})", R"({"address":"D100","values":[70000]})",
          R"({"address":"D100","values":["x"]})", R"({"address":"D100","values":[{}]})",
          R"({"address":"D100","values":[1],"as":"nope"})", R"({"address":"A0","values":[1]})",
          R"({"address":"D32767","values":[1,2]})", R"({"address":"IR0","values":[1]})",
          R"({"address":5,"values":[1]})", R"({"address":"D100","values":[1],"plc":3})"}) {
        auto a = call("POST", "/api/write", body);
        EXPECT_EQ(a.status, 400u) << body;
        EXPECT_TRUE(json(a).contains("error")) << body;
    }
    EXPECT_EQ(plc_.memory().words(Region::dm)[100], 0);
    EXPECT_EQ(plc_.memory().words(Region::auxiliary)[0], 0);
}

TEST_F(Api, ControlTakesTheChannelsRequests) {
    context_.options.control = true;
    auto a = call("POST", "/api/control", R"({"cmd":"mode","mode":"program"})");
    EXPECT_EQ(a.status, 200u) << a.body;
    EXPECT_EQ(plc_.mode(), plc::OperatingMode::program);
    EXPECT_EQ(call("POST", "/api/control", R"({"cmd":"fal","number":5,"message":"LOW"})").status,
              200u);
    auto status = json(call("GET", "/api/status"));
    EXPECT_EQ(status["mode"], "program");
    EXPECT_EQ(status["errors"][0]["code"], "4105");
    EXPECT_EQ(status["error_log"].size(), 1u);
    EXPECT_TRUE(status.contains("protections"));
    EXPECT_TRUE(status.contains("faults"));
    EXPECT_TRUE(status["connections"].is_array());
    EXPECT_EQ(call("POST", "/api/control", R"({"cmd":"nope"})").status, 400u);
    EXPECT_EQ(call("POST", "/api/control", "not json").status, 400u);
    EXPECT_EQ(call("POST", "/api/control", R"({"cmd":"status","plc":"other"})").status, 400u);
}

TEST_F(Api, ListsTheCpuUnits) {
    auto plcs = json(call("GET", "/api/plcs"));
    ASSERT_EQ(plcs["plcs"].size(), 1u);
    EXPECT_EQ(plcs["plcs"][0]["node"], 1);
    EXPECT_EQ(plcs["plcs"][0]["model"], plc_.profile().model);
    EXPECT_EQ(plcs["control"], false);
    // Whether POSTs need --http-token-file's token: the page asks for it when they do.
    EXPECT_EQ(plcs["token_required"], false);
    context_.options.token = "s3cret";
    EXPECT_EQ(json(call("GET", "/api/plcs"))["token_required"], true);
}

TEST_F(Api, ChoosesThePlantsCpuUnitByNameOrAddress) {
    plc::Plc second;
    server::ControlTarget t;
    t.plc = &second;
    t.name = "press2";
    t.addresses = {{2, 7}};
    context_.targets.push_back(t);
    second.memory().words(Region::dm)[0] = 42;
    EXPECT_EQ(json(call("GET", "/api/read?address=D0&plc=press2"))["values"], Json::array({42}));
    EXPECT_EQ(json(call("GET", "/api/read?address=D0&plc=2.7"))["values"], Json::array({42}));
    EXPECT_EQ(json(call("GET", "/api/read?address=D0"))["values"], Json::array({0}));
    EXPECT_EQ(call("GET", "/api/read?address=D0&plc=press9").status, 404u);
}

TEST_F(Api, ServesTheEmbeddedFilesAndAnswersUnknownRoutes) {
    auto index = call("GET", "/");
    EXPECT_EQ(index.status, 200u);
    EXPECT_EQ(index.content_type, "text/html; charset=utf-8");
    EXPECT_NE(index.body.find("<html"), std::string::npos);
    auto yaml = call("GET", "/openapi.yaml");
    EXPECT_EQ(yaml.status, 200u);
    EXPECT_NE(yaml.body.find("openapi: 3"), std::string::npos);
    auto chart = call("GET", "/chart.js");
    EXPECT_EQ(chart.status, 200u);
    EXPECT_GT(chart.body.size(), 100'000u);
    EXPECT_EQ(call("GET", "/nope").status, 404u);
    EXPECT_EQ(call("GET", "/api/nope").status, 404u);
    EXPECT_EQ(call("GET", "/../etc/passwd").status, 404u);
    EXPECT_EQ(call("POST", "/api/read").status, 405u);
    EXPECT_EQ(call("GET", "/api/write").status, 405u);
    EXPECT_EQ(call("DELETE", "/").status, 405u);
    EXPECT_EQ(call("GET", "http://x/").status, 400u);
}

TEST(ApiSecurity, ChecksHostOriginAndToken) {
    web::WebOptions o;
    o.port = 8080;
    auto check = [&](web::RequestMeta m) { return web::check_request(o, m); };
    const std::optional<std::string_view> json = "application/json";
    EXPECT_FALSE(check({"GET", "/", "127.0.0.1:8080", std::nullopt, std::nullopt}));
    EXPECT_FALSE(check({"GET", "/", "localhost:8080", std::nullopt, std::nullopt}));
    EXPECT_FALSE(check({"GET", "/", "[::1]:8080", std::nullopt, std::nullopt}));
    // DNS rebinding: a name that is not ours.
    EXPECT_EQ(check({"GET", "/", "evil.example:8080", std::nullopt, std::nullopt})->status, 403u);
    EXPECT_FALSE(
        check({"POST", "/api/write", "127.0.0.1:8080", "http://127.0.0.1:8080", {}, false, json}));
    EXPECT_FALSE(
        check({"POST", "/api/write", "127.0.0.1:8080", "HTTP://127.0.0.1:8080", {}, false, json}));
    EXPECT_EQ(
        check({"POST", "/api/write", "127.0.0.1:8080", "http://evil.example", {}, false, json})
            ->status,
        403u);
    // Only the page's own origin: not another IP literal, port, scheme or name for it.
    for (const char* other : {"http://127.0.0.2:9000", "http://127.0.0.1:9000", "http://127.0.0.1",
                              "https://127.0.0.1:8080", "http://localhost:8080", "null", ""})
        EXPECT_EQ(check({"POST", "/api/write", "127.0.0.1:8080", other, {}, false, json})->status,
                  403u)
            << other;
    // No Host (HTTP/1.0): no own origin to compare with.
    EXPECT_EQ(check({"POST", "/api/write", std::nullopt, "http://127.0.0.1:8080", {}, false, json})
                  ->status,
              403u);
    EXPECT_EQ(check({"GET", "/ws", "127.0.0.1:8080", "http://evil.example", {}, true})->status,
              403u);
    EXPECT_EQ(check({"GET", "/ws", "127.0.0.1:8080", "null", {}, true})->status, 403u);
    EXPECT_FALSE(check({"GET", "/ws", "127.0.0.1:8080", "http://127.0.0.1:8080", {}, true}));
    // A GET from another origin changes nothing: the browser's same-origin rule guards it.
    EXPECT_FALSE(check({"GET", "/api/read", "127.0.0.1:8080", "http://evil.example", {}}));
    o.allowed_hosts = {"plc-sim.lan"};
    EXPECT_FALSE(check(
        {"POST", "/api/write", "plc-sim.lan:8080", "http://plc-sim.lan:8080", {}, false, json}));
    o.allowed_origins = {"https://SCADA.lan"};
    EXPECT_FALSE(
        check({"POST", "/api/write", "127.0.0.1:8080", "https://scada.lan", {}, false, json}));
    EXPECT_FALSE(check({"GET", "/ws", "127.0.0.1:8080", "https://scada.lan", {}, true}));
    o.token = "s3cret";
    EXPECT_EQ(
        check({"POST", "/api/write", "127.0.0.1:8080", std::nullopt, std::nullopt, false, json})
            ->status,
        403u);
    EXPECT_FALSE(check(
        {"POST", "/api/write", "127.0.0.1:8080", std::nullopt, "Bearer s3cret", false, json}));
    // The scheme is case-insensitive (RFC 9110 11.1); the token is not.
    EXPECT_FALSE(check(
        {"POST", "/api/write", "127.0.0.1:8080", std::nullopt, "bearer s3cret", false, json}));
    EXPECT_FALSE(check(
        {"POST", "/api/write", "127.0.0.1:8080", std::nullopt, "BEARER s3cret", false, json}));
    EXPECT_EQ(
        check({"POST", "/api/write", "127.0.0.1:8080", std::nullopt, "BEARER S3CRET", false, json})
            ->status,
        403u);
    EXPECT_EQ(
        check({"POST", "/api/write", "127.0.0.1:8080", std::nullopt, "Basic s3cret", false, json})
            ->status,
        403u);
    EXPECT_EQ(check({"POST", "/api/write", "127.0.0.1:8080", std::nullopt, "Bearer", false, json})
                  ->status,
              403u);
    EXPECT_FALSE(check({"GET", "/api/read", "127.0.0.1:8080", std::nullopt, std::nullopt}));
}

TEST(ApiSecurity, APostNeedsAJsonContentType) {
    web::WebOptions o;
    auto status = [&](std::optional<std::string_view> type) {
        auto r = web::check_request(
            o, {"POST", "/api/control", "127.0.0.1", std::nullopt, std::nullopt, false, type});
        return r ? r->status : 0u;
    };
    EXPECT_EQ(status(std::nullopt), 415u);
    EXPECT_EQ(status("text/plain"), 415u);
    EXPECT_EQ(status("multipart/form-data; boundary=x"), 415u);
    EXPECT_EQ(status("application/json-seq"), 415u);
    EXPECT_EQ(status("application/json"), 0u);
    EXPECT_EQ(status("Application/JSON ; charset=UTF-8"), 0u);
    // A GET needs none.
    EXPECT_FALSE(web::check_request(
        o, {"GET", "/api/read", "127.0.0.1", std::nullopt, std::nullopt, false, std::nullopt}));
}

}  // namespace
}  // namespace fins::test
