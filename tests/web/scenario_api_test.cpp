// GET /api/scenario against a finsd running examples/scenarios/conveyor.toml: the tags
// with the types the file gives them, the events with their state, the actions of
// POST /api/control changing what it answers; 404 without a scenario; GET only.
#include <gtest/gtest.h>

#include <string>

#include "integration/support/finsd_process.hpp"
#include "integration/support/free_port.hpp"
#include "web_server.hpp"

namespace fins::test {
namespace {

using Json = nlohmann::json;

TEST(ScenarioApi, ListsTagsWithTypesAndEventsWithState) {
    ScratchDir dir("http-scenario-api");
    const auto port = free_tcp_port();
    const std::string conveyor = std::string(FINS_SOURCE_DIR) + "/examples/scenarios/conveyor.toml";
    Finsd finsd({"--http", "127.0.0.1:" + std::to_string(port), "--http-control", "--scenario",
                 conveyor, "--control", (dir.path() / "ctl.sock").string()});
    ASSERT_TRUE(finsd.started()) << finsd.result().err;
    HttpClient http(port);
    auto answer = http.request(http::verb::get, "/api/scenario");
    ASSERT_EQ(answer.result_int(), 200u) << answer.body();
    const auto j = body_json(answer);
    ASSERT_EQ(j["tags"].size(), 4u) << j;
    EXPECT_EQ(j["tags_total"], 4);
    // In file order. A link to a bit is a bool; a link without a type is an int16.
    EXPECT_EQ(j["tags"][0],
              (Json{{"address", "D20"}, {"type", "int16"}, {"words", 1}, {"kind", "link"}}));
    EXPECT_EQ(j["tags"][1]["address"], "CIO2.00");
    EXPECT_EQ(j["tags"][1]["type"], "bool");
    EXPECT_EQ(j["tags"][1]["words"], 0);
    EXPECT_EQ(j["tags"][2],
              (Json{{"address", "D21"}, {"type", "uint16"}, {"words", 1}, {"kind", "counter"}}));
    EXPECT_EQ(j["tags"][3]["address"], "D22");
    EXPECT_EQ(j["tags"][3]["type"], "uint32");
    EXPECT_EQ(j["tags"][3]["words"], 2);
    ASSERT_EQ(j["events"].size(), 2u);
    EXPECT_EQ(j["events"][0]["name"], "jam");
    EXPECT_EQ(j["events"][0]["fault"], "set");
    EXPECT_EQ(j["events"][0]["address"], "D20");
    EXPECT_EQ(j["events"][0]["every_s"], 300.0);
    EXPECT_EQ(j["events"][0]["active"], false);
    EXPECT_EQ(j["events"][0]["next_start_s"], 300.0);
    EXPECT_EQ(j["events"][1]["fault"], "fal");
    EXPECT_EQ(j["status"]["paused"], false);
    EXPECT_EQ(j["status"]["time"], "virtual");

    // The actions are POST /api/control's; GET /api/scenario shows their effect.
    EXPECT_EQ(
        http.request(http::verb::post, "/api/control", R"({"cmd":"scenario","action":"pause"})")
            .result_int(),
        200u);
    EXPECT_EQ(body_json(http.request(http::verb::get, "/api/scenario"))["status"]["paused"], true);
    EXPECT_EQ(http.request(http::verb::post, "/api/control",
                           R"({"cmd":"scenario","action":"trigger","event":"jam"})")
                  .result_int(),
              200u);
    const auto after = body_json(http.request(http::verb::get, "/api/scenario"));
    EXPECT_EQ(after["events"][0]["active"], true) << after["events"];

    const auto post = http.request(http::verb::post, "/api/scenario", "{}");
    EXPECT_EQ(post.result_int(), 405u);
    const auto unknown = http.request(http::verb::get, "/api/scenario?plc=nosuch");
    EXPECT_EQ(unknown.result_int(), 404u);
    EXPECT_TRUE(body_json(unknown).contains("error"));
    EXPECT_EQ(finsd.stop().exit_code, 0);
}

TEST(ScenarioApi, NoScenarioIsA404WithTheReason) {
    const auto port = free_tcp_port();
    Finsd finsd({"--http", "127.0.0.1:" + std::to_string(port)});
    ASSERT_TRUE(finsd.started()) << finsd.result().err;
    HttpClient http(port);
    const auto answer = http.request(http::verb::get, "/api/scenario");
    EXPECT_EQ(answer.result_int(), 404u);
    EXPECT_NE(body_json(answer)["error"].get<std::string>().find("runs no scenario"),
              std::string::npos);
    EXPECT_EQ(finsd.stop().exit_code, 0);
}

}  // namespace
}  // namespace fins::test
