// GET /api/plcs (web/plc_listing.hpp): pages and their totals, bad paging parameters, the
// listing following a unit's change, and FINS served while a large plant is listed.
#include <gtest/gtest.h>

#include <array>
#include <chrono>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include <boost/asio/io_context.hpp>
#include <boost/asio/ip/udp.hpp>
#include <boost/asio/post.hpp>
#include <nlohmann/json.hpp>

#include "fins/byte_io.hpp"
#include "fins/commands/memory_area.hpp"
#include "fins/frame.hpp"
#include "plc/plc.hpp"
#include "server/sessions/server.hpp"
#include "web/api.hpp"
#include "web_server.hpp"

namespace fins::test {
namespace {

using Json = nlohmann::json;

// `units` CPU Units named unit1.. on networks of 250 nodes, answered by plain calls.
class Listing : public ::testing::Test {
  protected:
    void make(std::size_t units) {
        for (std::size_t i = 0; i < units; ++i) {
            plcs_.push_back(std::make_unique<plc::Plc>());
            server::ControlTarget t;
            t.plc = plcs_.back().get();
            t.name = "unit" + std::to_string(i + 1);
            t.addresses = {
                {static_cast<std::uint8_t>(1 + i / 250), static_cast<std::uint8_t>(1 + i % 250)}};
            context_.targets.push_back(t);
        }
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
    Json get(std::string_view target, unsigned status = 200) {
        const auto a = call("GET", target);
        EXPECT_EQ(a.status, status) << target << ": " << a.body;
        EXPECT_EQ(a.content_type, "application/json");
        return Json::parse(a.body, nullptr, false);
    }
    static std::vector<std::string> names(const Json& listing) {
        std::vector<std::string> out;
        for (const auto& p : listing["plcs"])
            out.push_back(p["name"].get<std::string>());
        return out;
    }

    std::vector<std::unique_ptr<plc::Plc>> plcs_;
    web::WebContext context_;
};

TEST_F(Listing, WithoutParametersListsEveryUnitAndSaysThereIsNoNextPage) {
    make(7);
    const auto j = get("/api/plcs");
    ASSERT_EQ(j["plcs"].size(), 7u);
    EXPECT_EQ(j["plcs"][6]["name"], "unit7");
    EXPECT_EQ(j["total"], 7);
    EXPECT_EQ(j["offset"], 0);
    EXPECT_TRUE(j["limit"].is_null());
    EXPECT_TRUE(j["next"].is_null());
    EXPECT_EQ(j["control"], false);
    EXPECT_EQ(j["token_required"], false);
}

TEST_F(Listing, PagesFollowEachOtherThroughNextToTheLastUnit) {
    make(7);
    auto j = get("/api/plcs?limit=3");
    EXPECT_EQ(names(j), (std::vector<std::string>{"unit1", "unit2", "unit3"}));
    EXPECT_EQ(j["total"], 7);
    EXPECT_EQ(j["limit"], 3);
    ASSERT_EQ(j["next"], 3);
    j = get("/api/plcs?offset=3&limit=3");
    EXPECT_EQ(names(j), (std::vector<std::string>{"unit4", "unit5", "unit6"}));
    ASSERT_EQ(j["next"], 6);
    j = get("/api/plcs?offset=6&limit=3");
    EXPECT_EQ(names(j), (std::vector<std::string>{"unit7"}));
    EXPECT_TRUE(j["next"].is_null());
    // Following next from the start gathers every unit once, in order.
    std::vector<std::string> all;
    Json next = 0;
    for (int pages = 0; !next.is_null() && pages < 10; ++pages) {
        j = get("/api/plcs?limit=2&offset=" + std::to_string(next.get<std::size_t>()));
        for (auto& n : names(j))
            all.push_back(n);
        next = j["next"];
    }
    EXPECT_EQ(all, names(get("/api/plcs")));
}

TEST_F(Listing, AnEmptyPageStillCarriesTheTotal) {
    make(4);
    auto j = get("/api/plcs?limit=0");
    EXPECT_TRUE(j["plcs"].empty());
    EXPECT_EQ(j["total"], 4);
    EXPECT_EQ(j["next"], 0);
    // Past the last unit: an empty page, no next.
    j = get("/api/plcs?offset=9&limit=5");
    EXPECT_TRUE(j["plcs"].empty());
    EXPECT_EQ(j["total"], 4);
    EXPECT_TRUE(j["next"].is_null());
    j = get("/api/plcs?offset=18446744073709551615&limit=18446744073709551615");
    EXPECT_TRUE(j["plcs"].empty());
    EXPECT_TRUE(j["next"].is_null());
    j = get("/api/plcs?offset=4");
    EXPECT_TRUE(j["plcs"].empty());
    EXPECT_TRUE(j["next"].is_null());
}

TEST_F(Listing, RefusesBadPagingParametersWith400AndAJsonError) {
    make(3);
    for (const char* target :
         {"/api/plcs?offset=-1", "/api/plcs?offset=x",
          "/api/plcs?offset=", "/api/plcs?limit=", "/api/plcs?limit=-5", "/api/plcs?limit=2.5",
          "/api/plcs?limit=1e3", "/api/plcs?limit=%2B3", "/api/plcs?offset=0x10",
          "/api/plcs?limit=99999999999999999999", "/api/plcs?offset"}) {
        const auto j = get(target, 400);
        ASSERT_TRUE(j.is_object()) << target;
        ASSERT_TRUE(j["error"].is_string()) << target;
        const std::string error = j["error"];
        EXPECT_TRUE(error.find("offset=") == 0 || error.find("limit=") == 0) << error;
    }
    // What POST and others get: 405, as before.
    EXPECT_EQ(call("POST", "/api/plcs").status, 405u);
}

TEST_F(Listing, ShowsAUnitsModeChangeAndOnlyThatUnitsEntryChanges) {
    make(5);
    context_.options.control = true;
    const auto before = get("/api/plcs");
    for (const auto& p : before["plcs"])
        EXPECT_EQ(p["mode"], "run");
    const auto changed =
        call("POST", "/api/control", R"({"cmd":"mode","mode":"program","plc":"unit3"})");
    ASSERT_EQ(changed.status, 200u) << changed.body;
    const auto after = get("/api/plcs");
    ASSERT_EQ(after["plcs"].size(), 5u);
    EXPECT_EQ(after["plcs"][2]["mode"], "program");
    for (std::size_t i : {0u, 1u, 3u, 4u})
        EXPECT_EQ(after["plcs"][i], before["plcs"][i]) << i;
    // A page that holds it shows it too.
    EXPECT_EQ(get("/api/plcs?offset=2&limit=1")["plcs"][0]["mode"], "program");
}

// A FINS request to a unit of a 2,000-unit plant, sent as the listing begins, is answered
// before the listing is: the listing gives the thread back between its slices. (Order
// only: how long each takes is bench/web_plcs.cpp's.)
TEST_F(Listing, AnswersFinsToAUnitWhileALargePlantIsListed) {
    make(2000);
    namespace asio = boost::asio;
    asio::io_context io{1};
    context_.executor = io.get_executor();
    context_.options.listing_slice = std::chrono::microseconds(0);  // one entry a slice
    plc::Plc& polled = *plcs_[1234];
    polled.memory().words(Region::dm)[0] = 0x1234;
    server::ServerOptions options;
    options.port = 0;
    auto server = server::Server::start(io, polled, options);
    ASSERT_TRUE(server) << server.error().message();

    // A 1-word read of D0, in the server's socket before the listing starts.
    std::array<std::uint8_t, 32> params{};
    ByteWriter pw{params};
    MemoryAreaRead{{0x82, 0, 0}, 1}.encode(pw);
    Header h;
    h.destination = (*server)->address();
    h.source = {0, 200, 0};
    h.service_id = 7;
    std::array<std::uint8_t, max_frame_size> frame{};
    const auto n = encode_request(h, MemoryAreaRead::code, pw.written(), frame);
    ASSERT_TRUE(n);
    asio::ip::udp::socket client(io,
                                 asio::ip::udp::endpoint(asio::ip::make_address("127.0.0.1"), 0));
    const asio::ip::udp::endpoint to(asio::ip::make_address("127.0.0.1"), (*server)->udp_port());
    client.send_to(asio::buffer(frame.data(), *n), to);

    std::vector<std::string> order;
    std::array<std::uint8_t, max_frame_size> in{};
    asio::ip::udp::endpoint from;
    std::vector<std::uint8_t> answer;
    client.async_receive_from(
        asio::buffer(in), from, [&](boost::system::error_code ec, std::size_t got) {
            ASSERT_FALSE(ec) << ec.message();
            order.push_back("fins");
            answer.assign(in.begin(), in.begin() + static_cast<std::ptrdiff_t>(got));
        });
    web::HttpAnswer listing;
    web::handle_request(context_, "GET", "/api/plcs", {}, [&](web::HttpAnswer a) {
        order.push_back("plcs");
        listing = std::move(a);
    });
    // Bounded: both answers, or a minute at most.
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(60);
    while (order.size() < 2 && std::chrono::steady_clock::now() < deadline)
        io.run_one_for(std::chrono::milliseconds(100));
    (*server)->stop();
    ASSERT_EQ(order, (std::vector<std::string>{"fins", "plcs"}));

    const auto response = decode_response(Bytes{answer.data(), answer.size()});
    ASSERT_TRUE(response);
    EXPECT_TRUE(response->code.ok());
    EXPECT_EQ(response->header.service_id, 7);
    EXPECT_EQ(std::vector<std::uint8_t>(response->data.begin(), response->data.end()),
              (std::vector<std::uint8_t>{0x12, 0x34}));
    ASSERT_EQ(listing.status, 200u);
    const auto j = Json::parse(listing.body);
    ASSERT_EQ(j["plcs"].size(), 2000u);
    EXPECT_EQ(j["total"], 2000);
    EXPECT_EQ(j["plcs"][1999]["name"], "unit2000");
}

// A slice that throws (here the describe hook, at the 30th unit, in a slice posted to the
// io_context) ends that request with a 500 JSON error; io_context::run goes on.
TEST_F(Listing, ASliceThatThrowsAnswers500AndTheIoContextGoesOn) {
    make(50);
    boost::asio::io_context io{1};
    context_.executor = io.get_executor();
    context_.options.listing_slice = std::chrono::microseconds(0);
    context_.describe = [](const server::ControlTarget& t, Json&) {
        if (t.name == "unit30") throw std::runtime_error("describe failed");
    };
    std::vector<web::HttpAnswer> answers;
    web::handle_request(context_, "GET", "/api/plcs", {},
                        [&](web::HttpAnswer a) { answers.push_back(std::move(a)); });
    bool after = false;
    boost::asio::post(io, [&] { after = true; });
    for (int i = 0; i < 1000 && (answers.empty() || !after); ++i)
        ASSERT_NO_THROW(io.run_one_for(std::chrono::milliseconds(100)));
    ASSERT_EQ(answers.size(), 1u);
    EXPECT_EQ(answers[0].status, 500u);
    EXPECT_TRUE(Json::parse(answers[0].body)["error"].is_string());
    EXPECT_TRUE(after);
    io.restart();
    EXPECT_EQ(io.poll(), 0u);  // nothing left: the listing stopped there
}

// Through the HTTP server (which lists in slices on its io_context): whole and paged.
TEST(ListingOverHttp, ListsInSlicesAndPages) {
    WebServer server({}, 300);
    HttpClient client(server.port());
    auto r = client.request(http::verb::get, "/api/plcs");
    ASSERT_EQ(r.result(), http::status::ok);
    auto j = body_json(r);
    ASSERT_EQ(j["plcs"].size(), 300u);
    EXPECT_EQ(j["plcs"][299]["name"], "plc300");
    EXPECT_TRUE(j["next"].is_null());
    r = client.request(http::verb::get, "/api/plcs?offset=290&limit=20");
    j = body_json(r);
    ASSERT_EQ(j["plcs"].size(), 10u);
    EXPECT_EQ(j["plcs"][0]["name"], "plc291");
    EXPECT_EQ(j["total"], 300);
    EXPECT_TRUE(j["next"].is_null());
    r = client.request(http::verb::get, "/api/plcs?limit=abc");
    EXPECT_EQ(r.result(), http::status::bad_request);
    EXPECT_TRUE(body_json(r)["error"].is_string());
}

}  // namespace
}  // namespace fins::test
