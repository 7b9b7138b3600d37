// WebSocket subscriptions as a pure state machine (web/subscriptions.hpp): snapshots,
// deltas, coalescing, seq, resync and resume, with time passed in (no waiting).
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <string>
#include <vector>

#include <fmt/core.h>
#include <nlohmann/json.hpp>

#include "plc/plc.hpp"
#include "web/subscriptions.hpp"

namespace fins::test {
namespace {

using Json = nlohmann::json;
using namespace std::chrono_literals;

class Subs : public ::testing::Test {
  protected:
    Subs() {
        server::ControlTarget t;
        t.plc = &plc_;
        t.addresses = {{0, 1}};
        context_.targets.push_back(t);
        // Powered up a minute before the test starts: its cycle-time statistics have
        // settled, so the status topic changes only when the test changes the PLC.
        plc_.power_on(wall0_ - 1min);
    }
    std::vector<Json> send(web::Subscriptions& s, const std::string& text) {
        std::vector<std::string> out;
        s.on_message(text, out);
        return parse(out);
    }
    std::vector<Json> poll(web::Subscriptions& s) {
        std::vector<std::string> out;
        s.poll(now_, wall(), out);
        return parse(out);
    }
    static std::vector<Json> parse(const std::vector<std::string>& texts) {
        std::vector<Json> out;
        for (const auto& t : texts)
            out.push_back(Json::parse(t));
        return out;
    }
    std::span<std::uint16_t> dm() { return plc_.memory().words(Region::dm); }
    // The wall time that goes with now_ (both move only when the test moves now_).
    [[nodiscard]] std::chrono::system_clock::time_point wall() const {
        return wall0_ +
               std::chrono::duration_cast<std::chrono::system_clock::duration>(now_ - steady0_);
    }

    plc::Plc plc_;
    web::WebContext context_;
    web::SteadyTime now_ = web::SteadyTime{} + 1h;
    const web::SteadyTime steady0_ = now_;
    const std::chrono::system_clock::time_point wall0_ = std::chrono::system_clock::now();
};

TEST_F(Subs, SendsASnapshotThenOnlyWhatChanged) {
    web::Subscriptions s(context_, "abc");
    dm()[1] = 5;
    EXPECT_TRUE(send(s, R"({"op":"subscribe","id":"s1","address":"D0","count":4})").empty());
    auto first = poll(s);
    ASSERT_EQ(first.size(), 1u);
    EXPECT_EQ(first[0], Json::parse(R"({"seq":1,"id":"s1","type":"snapshot","values":[0,5,0,0]})"));
    now_ += 1s;
    EXPECT_TRUE(poll(s).empty());  // nothing changed: nothing sent
    dm()[2] = 9;
    dm()[3] = 1;
    now_ += 100ms;  // the range is read once per interval
    auto delta = poll(s);
    ASSERT_EQ(delta.size(), 1u);
    EXPECT_EQ(delta[0],
              Json::parse(R"({"seq":2,"id":"s1","type":"delta","changes":[[2,9],[3,1]]})"));
}

TEST_F(Subs, CoalescesChangesToOneMessagePerInterval) {
    web::Subscriptions s(context_, "abc");
    send(s, R"({"op":"subscribe","id":"s1","address":"D0","count":2})");
    ASSERT_EQ(poll(s).size(), 1u);
    // Five changes within one interval (100 ms): the first goes out after it, as one delta
    // of the final values.
    for (int i = 1; i <= 5; ++i) {
        dm()[0] = static_cast<std::uint16_t>(i);
        now_ += 10ms;
        EXPECT_TRUE(poll(s).empty()) << i;
    }
    dm()[1] = 3;
    now_ += 50ms;  // 100 ms since the snapshot
    auto out = poll(s);
    ASSERT_EQ(out.size(), 1u);
    EXPECT_EQ(out[0]["changes"], Json::parse("[[0,5],[1,3]]"));
    // A change back to what was last sent within the interval sends nothing.
    dm()[0] = 6;
    dm()[0] = 5;
    now_ += 100ms;
    EXPECT_TRUE(poll(s).empty());
}

TEST_F(Subs, TypedViewsAndTopics) {
    web::Subscriptions s(context_, "abc");
    send(s, R"({"op":"subscribe","id":"f","address":"D10","count":1,"as":"float"})");
    send(s, R"({"op":"subscribe","id":"st","topic":"status"})");
    dm()[11] = 0x3FC0;  // 1.5f
    auto out = poll(s);
    ASSERT_EQ(out.size(), 2u);
    EXPECT_EQ(out[0]["values"], Json::array({1.5}));
    EXPECT_EQ(out[1]["id"], "st");
    EXPECT_EQ(out[1]["value"]["mode"], "run");
    now_ += 1s;
    EXPECT_TRUE(poll(s).empty());
    plc_.change_mode(plc::OperatingMode::program, wall());
    now_ += web::topic_interval;  // a topic is built again at most this often
    out = poll(s);
    ASSERT_EQ(out.size(), 1u);
    EXPECT_EQ(out[0]["value"]["mode"], "program");
    EXPECT_EQ(out[0]["seq"], 3);
}

TEST_F(Subs, RefusesBadRequestsWithAnErrorMessage) {
    web::Subscriptions s(context_, "abc");
    for (const char* m :
         {"nope", "[]", R"({"op":"dance"})", R"({"op":"subscribe"})",
          R"({"op":"subscribe","id":"a"})", R"({"op":"subscribe","id":"a","address":"Q1"})",
          R"({"op":"subscribe","id":"a","address":"D0","count":0})",
          R"({"op":"subscribe","id":"a","address":"D0","count":-1})",
          R"({"op":"subscribe","id":"a","topic":"weather"})",
          R"({"op":"subscribe","id":"a","address":"D0","plc":"x"})",
          R"({"op":"unsubscribe","id":"zz"})", R"({"op":"resume"})"}) {
        auto out = send(s, m);
        ASSERT_EQ(out.size(), 1u) << m;
        EXPECT_EQ(out[0]["type"], "error") << m;
    }
    EXPECT_EQ(s.size(), 0u);
    context_.options.max_subscriptions = 2;
    send(s, R"({"op":"subscribe","id":"a","address":"D0"})");
    send(s, R"({"op":"subscribe","id":"b","address":"D0"})");
    EXPECT_EQ(send(s, R"({"op":"subscribe","id":"c","address":"D0"})").size(), 1u);
    EXPECT_TRUE(send(s, R"({"op":"subscribe","id":"a","address":"D5"})").empty());  // replaces
    EXPECT_EQ(s.size(), 2u);
    EXPECT_TRUE(send(s, R"({"op":"unsubscribe","id":"a"})").empty());
    EXPECT_EQ(s.size(), 1u);
}

// Issue 16's cost bound: every connection watching the same range shares one Watch,
// read and printed once per interval; each message's values are the same buffer.
TEST_F(Subs, SubscribersOfOneRangeShareOneWatchAndItsText) {
    web::Subscriptions a(context_, "a");
    web::Subscriptions b(context_, "b");
    std::vector<web::Message> ma, mb;
    a.on_message(R"({"op":"subscribe","id":"x","address":"D0","count":3})", ma);
    b.on_message(R"({"op":"subscribe","id":"y","address":"D0","count":3})", mb);
    b.on_message(R"({"op":"subscribe","id":"z","address":"D0","count":3,"as":"hex"})", mb);
    EXPECT_EQ(context_.watches->size(), 2u);  // uint16 D0-D2 (twice), hex D0-D2
    dm()[0] = 7;
    const auto wall = std::chrono::system_clock::now();
    a.poll(now_, wall, ma);
    b.poll(now_, wall, mb);
    ASSERT_EQ(ma.size(), 1u);
    ASSERT_EQ(mb.size(), 2u);
    ASSERT_NE(ma[0].body, nullptr);
    EXPECT_EQ(ma[0].body.get(), mb[0].body.get());  // one snapshot text, not two
    EXPECT_EQ(Json::parse(ma[0].text()),
              Json::parse(R"({"seq":1,"id":"x","type":"snapshot","values":[7,0,0]})"));
    EXPECT_EQ(Json::parse(mb[1].text())["values"], Json::parse(R"(["0x0007","0x0000","0x0000"])"));
    ma.clear();
    mb.clear();
    dm()[1] = 5;
    now_ += 100ms;
    a.poll(now_, wall, ma);
    b.poll(now_, wall, mb);
    ASSERT_EQ(ma.size(), 1u);
    ASSERT_EQ(mb.size(), 2u);
    EXPECT_EQ(*ma[0].body, "[[1,5]]");
    EXPECT_EQ(ma[0].body.get(), mb[0].body.get());  // one delta text
    EXPECT_EQ(Json::parse(mb[0].text()),
              Json::parse(R"({"seq":3,"id":"y","type":"delta","changes":[[1,5]]})"));
    EXPECT_EQ(Json::parse(mb[1].text())["changes"], Json::parse(R"([[1,"0x0005"]])"));
    // A subscriber that joins later starts from the shared snapshot, then shares deltas.
    web::Subscriptions c(context_, "c");
    std::vector<web::Message> mc;
    c.on_message(R"({"op":"subscribe","id":"w","address":"D0","count":3})", mc);
    c.poll(now_ + 10ms, wall, mc);
    ASSERT_EQ(mc.size(), 1u);
    EXPECT_EQ(Json::parse(mc[0].text())["values"], Json::parse("[7,5,0]"));
    // Nobody watches: the watches go.
    a.on_message(R"({"op":"unsubscribe","id":"x"})", ma);
    b.on_message(R"({"op":"unsubscribe","id":"y"})", mb);
    b.on_message(R"({"op":"unsubscribe","id":"z"})", mb);
    c.on_message(R"({"op":"unsubscribe","id":"w"})", mc);
    EXPECT_EQ(context_.watches->size(), 0u);
}

TEST_F(Subs, ResyncSendsSnapshotsAgain) {
    web::Subscriptions s(context_, "abc");
    send(s, R"({"op":"subscribe","id":"s1","address":"D0","count":2})");
    poll(s);
    s.resync();
    auto out = poll(s);
    ASSERT_EQ(out.size(), 1u);
    EXPECT_EQ(out[0]["type"], "snapshot");
    EXPECT_EQ(out[0]["seq"], 2);
}

TEST_F(Subs, ResumeReplaysWhatWasMissedOrResyncs) {
    web::ResumeStore store(context_.options);
    auto s = std::make_unique<web::Subscriptions>(context_, "abc");
    send(*s, R"({"op":"subscribe","id":"s1","address":"D0","count":2})");
    poll(*s);  // seq 1, the client saw it
    for (std::uint16_t i = 1; i <= 3; ++i) {
        dm()[0] = i;
        now_ += 100ms;
        poll(*s);  // seq 2-4, lost with the connection
    }
    store.keep(std::move(s), now_);
    web::Subscriptions fresh(context_, "def");
    std::vector<std::string> ignored;
    auto resume = fresh.on_message(R"({"op":"resume","session":"abc","seq":1})", ignored);
    ASSERT_TRUE(resume);
    EXPECT_EQ(store.take("nope", now_), nullptr);
    auto old = store.take(resume->session, now_);
    ASSERT_NE(old, nullptr);
    std::vector<std::string> replay;
    EXPECT_TRUE(old->replay_after(resume->seq, replay));
    ASSERT_EQ(replay.size(), 3u);
    EXPECT_EQ(Json::parse(replay[0])["seq"], 2);
    EXPECT_EQ(Json::parse(replay[2])["changes"], Json::parse("[[0,3]]"));
    // A seq older than the history: fresh snapshots, seq still rising.
    send(*old, R"({"op":"subscribe","id":"big","address":"D100","count":1000})");
    for (std::uint16_t i = 1; i <= 100; ++i) {  // ~10 KB a delta: past the 256 KiB kept
        std::fill_n(dm().begin() + 100, 1000, i);
        now_ += 100ms;
        poll(*old);
    }
    replay.clear();
    EXPECT_FALSE(old->replay_after(1, replay));
    EXPECT_TRUE(replay.empty());
    const auto before = old->seq();
    auto out = poll(*old);
    ASSERT_EQ(out.size(), 2u);
    EXPECT_EQ(out[0]["type"], "snapshot");
    EXPECT_EQ(out[1]["type"], "snapshot");
    EXPECT_EQ(out[0]["seq"], before + 1);
}

TEST_F(Subs, TheStoreIsBoundedInCountAndTime) {
    context_.options.max_resumable = 2;
    web::ResumeStore store(context_.options);
    for (const char* id : {"a", "b", "c"})
        store.keep(std::make_unique<web::Subscriptions>(context_, id), now_);
    EXPECT_EQ(store.size(), 2u);
    EXPECT_EQ(store.take("a", now_), nullptr);
    EXPECT_EQ(store.take("c", now_ + context_.options.resume_window), nullptr);  // expired
}

TEST_F(Subs, ABudgetedPollRefreshesRoundRobinWithinItsBudget) {
    // Three subscriptions of 1,000 words each; a budget of 1,500 words per poll refreshes
    // (and sends for) at most two, and the one left waiting goes first at the next poll.
    web::Subscriptions s(context_, "x");
    for (const char* id : {"a", "b", "c"})
        send(s, fmt::format(R"({{"op":"subscribe","id":"{}","address":"D{}","count":1000}})", id,
                            id[0] == 'a'   ? 0
                            : id[0] == 'b' ? 1000
                                           : 2000));
    const auto ids = [&](std::size_t budget, std::size_t* left = nullptr) {
        std::vector<web::Message> out;
        s.poll(now_, wall(), out, budget);
        if (left != nullptr) *left = budget;
        std::vector<std::string> names;
        for (const auto& m : out)
            names.push_back(Json::parse(m.text())["id"].get<std::string>());
        return names;
    };
    std::size_t left = 0;
    EXPECT_EQ(ids(1500, &left), (std::vector<std::string>{"a", "b"}));  // b: the one beyond
    EXPECT_EQ(left, 0u);
    EXPECT_EQ(ids(1500), (std::vector<std::string>{"c"}));  // not due again before interval
    now_ += context_.options.min_interval;
    std::fill_n(dm().begin(), 3000, std::uint16_t{7});
    EXPECT_EQ(ids(1500), (std::vector<std::string>{"c", "a"}));  // c first: it waited
    EXPECT_EQ(ids(0), (std::vector<std::string>{}));             // no budget: nothing read
    EXPECT_EQ(ids(1500), (std::vector<std::string>{"b"}));
}

}  // namespace
}  // namespace fins::test
