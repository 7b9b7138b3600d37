// RequestTracker per request (issue 27, "one engine"): finsd's network instructions run
// on the client's tracker, each request with its own destination and source, a sink that
// may refuse one request's frame, and an owner's check of the way an answer came back.
#include <gtest/gtest.h>

#include <set>
#include <vector>

#include "tracker_fixture.hpp"

namespace fins::test {
namespace {

// A sink that refuses the frames of some tags (or only their last attempt), and records
// every tag sent and every unanswered transmission.
struct RouteWire : FrameSink {
    void send_frame(Bytes frame) override { frames.emplace_back(frame.begin(), frame.end()); }
    std::error_code send_request(Bytes frame, std::uintptr_t tag, bool last) override {
        tags.push_back(tag);
        lasts.push_back(last);
        if (refuse.count(tag) != 0 || (last && refuse_last.count(tag) != 0)) return refusal;
        send_frame(frame);
        return {};
    }
    void unanswered(std::uintptr_t tag) override { unanswered_tags.push_back(tag); }

    std::set<std::uintptr_t> refuse;
    std::set<std::uintptr_t> refuse_last;
    std::error_code refusal = make_error_code(ClientError::not_connected);
    std::vector<std::vector<std::uint8_t>> frames;
    std::vector<std::uintptr_t> tags;
    std::vector<bool> lasts;
    std::vector<std::uintptr_t> unanswered_tags;
};

// An owner's check: takes an answer only for the tags it allows.
struct RouteCheck : AnswerCheck {
    bool answers(std::uintptr_t tag, const Header& request, const Header& response) override {
        asked.push_back(tag);
        last_request = request;
        last_response = response;
        return allowed.count(tag) != 0;
    }
    std::set<std::uintptr_t> allowed;
    std::vector<std::uintptr_t> asked;
    Header last_request;
    Header last_response;
};

inline constexpr NodeAddress other_plc{1, 30, 0};
inline constexpr NodeAddress other_host{0, 21, 0};

class TrackerRoutes : public ::testing::Test {
  protected:
    TrackerRoutes() { tracker.link_up(plc, host, t0); }

    RequestOptions to(NodeAddress destination, std::uintptr_t tag) {
        RequestOptions o;
        o.destination = destination;
        o.source = other_host;
        o.tag = tag;
        return o;
    }
    void submit(Outcome& o, const RequestOptions& options, RequestTiming timing = {}) {
        ASSERT_TRUE(
            tracker.submit(read_code, read_params, timing, o.callback(), t0, options).has_value());
    }
    Bytes last() const { return Bytes{wire.frames.back().data(), wire.frames.back().size()}; }

    RouteWire wire;
    RequestTracker tracker{wire};
};

// A request names its own destination and source; the link's are the default. The
// answer must come from its destination: the link's node answering is not its answer.
TEST_F(TrackerRoutes, PerRequestDestinationAndSourceAreSentAndAnswered) {
    Outcome own, linked;
    submit(own, to(other_plc, 7));
    const auto own_frame = wire.frames.back();
    EXPECT_EQ(own_frame[3], 1);   // DNA
    EXPECT_EQ(own_frame[4], 30);  // DA1
    EXPECT_EQ(own_frame[7], 21);  // SA1
    EXPECT_EQ(wire.tags.back(), 7u);
    submit(linked, RequestOptions{});
    EXPECT_EQ(wire.frames.back()[4], plc.node);
    EXPECT_EQ(wire.frames.back()[7], host.node);

    const Bytes own_bytes{own_frame.data(), own_frame.size()};
    auto from_link_node = answer(own_bytes);
    from_link_node[6] = plc.network;  // SNA, SA1: the link's destination answers
    from_link_node[7] = plc.node;
    EXPECT_EQ(tracker.on_frame(from_link_node, t0), RequestTracker::Disposition::invalid);
    EXPECT_FALSE(own.result);
    EXPECT_EQ(tracker.on_frame(answer(own_bytes), t0), RequestTracker::Disposition::matched);
    ASSERT_TRUE(own.result && own.result->has_value());
    EXPECT_EQ(tracker.on_frame(answer(last(), 0, {}, plc), t0),
              RequestTracker::Disposition::matched);
    EXPECT_TRUE(linked.result && linked.result->has_value());
}

// The sink refuses one request's frame (no route to its node): that request alone fails,
// with the sink's error, at the next on_timer() (never inside submit()); the link stays
// up, the other request is answered, and the refused SID is clean (nothing was sent).
TEST_F(TrackerRoutes, RefusedSendFailsOnlyThatRequest) {
    wire.refuse.insert(2);
    wire.refusal = make_error_code(ClientError::connection_closed);
    Outcome good, refused;
    submit(good, to(other_plc, 1));
    const auto good_frame = wire.frames.back();
    submit(refused, to(other_plc, 2));
    EXPECT_FALSE(refused.result);  // not inside submit()
    EXPECT_EQ(wire.frames.size(), 1u);
    EXPECT_EQ(tracker.next_deadline(), t0);
    tracker.on_timer(t0);
    ASSERT_TRUE(refused.result);
    ASSERT_FALSE(refused.result->has_value());
    EXPECT_EQ(refused.result->error(), make_error_code(ClientError::connection_closed));
    EXPECT_EQ(tracker.stats().refused, 1u);
    EXPECT_EQ(tracker.stats().quarantined, 0u);
    EXPECT_TRUE(wire.unanswered_tags.empty());
    EXPECT_TRUE(tracker.is_link_up());
    EXPECT_EQ(tracker.in_flight(), 1u);
    EXPECT_FALSE(good.result);
    EXPECT_EQ(
        tracker.on_frame(answer(Bytes{good_frame.data(), good_frame.size()}, 0, {}, other_plc), t0),
        RequestTracker::Disposition::matched);
    EXPECT_TRUE(good.result && good.result->has_value());
}

// A sink that refuses only the last attempt (the kernel refused a frame that no retry
// follows): the first transmission timed out (the sink hears of it), the retry is refused
// and the request fails with the sink's error; its SID is quarantined for the
// transmission that went out unanswered, for the request's own quarantine.
TEST_F(TrackerRoutes, RefusedRetryFailsWithTheSinksErrorAndQuarantinesTheSid) {
    wire.refuse_last.insert(4);
    Outcome o;
    auto options = to(other_plc, 4);
    options.quarantine = 30s;
    submit(o, options, RequestTiming{100ms, 1});
    const auto sid = wire.frames.back()[9];
    EXPECT_EQ(wire.lasts, (std::vector<bool>{false}));
    tracker.on_timer(t0 + 100ms);
    EXPECT_EQ(wire.unanswered_tags, (std::vector<std::uintptr_t>{4}));
    EXPECT_EQ(wire.lasts, (std::vector<bool>{false, true}));
    ASSERT_TRUE(o.result);
    EXPECT_EQ(o.result->error(), make_error_code(ClientError::not_connected));
    EXPECT_TRUE(tracker.service_ids().is_quarantined(sid));
    EXPECT_EQ(tracker.service_ids().quarantine(), default_timeout * default_quarantine_timeouts);
    // Its own 30 s, not the tracker's 4 s: still quarantined after 10 s.
    SidPool probe = tracker.service_ids();
    for (int i = 0; i < 255; ++i)
        (void)probe.acquire(t0 + 10s);
    EXPECT_FALSE(probe.acquire(t0 + 10s).has_value());
    EXPECT_TRUE(probe.acquire(t0 + 31s).has_value());
}

// Every transmission that times out is reported with its tag, retries included.
TEST_F(TrackerRoutes, EveryTimedOutTransmissionIsReportedToTheSink) {
    Outcome o;
    submit(o, to(other_plc, 9), RequestTiming{100ms, 2});
    tracker.on_timer(t0 + 100ms);
    tracker.on_timer(t0 + 200ms);
    tracker.on_timer(t0 + 300ms);
    EXPECT_EQ(wire.unanswered_tags, (std::vector<std::uintptr_t>{9, 9, 9}));
    ASSERT_TRUE(o.result);
    EXPECT_EQ(o.result->error(), make_error_code(ClientError::timeout));
    EXPECT_EQ(wire.frames.size(), 3u);
}

// The owner's check decides which answer is the request's (the way it came back): a
// vetoed answer leaves the request in flight (counted invalid); an allowed one completes
// it, even with addresses a FINS/TCP connection rewrote (its own node for this node).
TEST_F(TrackerRoutes, AnswerCheckVetoesOrTakesAnAnswer) {
    Outcome o;
    submit(o, to(other_plc, 3));
    auto reply = answer(last(), 0, {}, other_plc);
    RouteCheck check;
    EXPECT_EQ(tracker.on_frame(reply, t0, &check), RequestTracker::Disposition::invalid);
    EXPECT_EQ(check.asked, (std::vector<std::uintptr_t>{3}));
    EXPECT_EQ(check.last_request.destination, other_plc);
    EXPECT_FALSE(o.result);
    EXPECT_EQ(tracker.stats().invalid_discarded, 1u);
    EXPECT_EQ(tracker.in_flight(), 1u);

    check.allowed.insert(3);
    reply[4] = 0x33;  // DA1: this node as the connection's handshake named it
    EXPECT_EQ(tracker.on_frame(reply, t0), RequestTracker::Disposition::invalid);
    EXPECT_EQ(tracker.on_frame(reply, t0, &check), RequestTracker::Disposition::matched);
    EXPECT_EQ(check.last_response.destination.node, 0x33);
    ASSERT_TRUE(o.result && o.result->has_value());
}

// A frame that asks for no answer goes to its own destination too; a refusal is the
// caller's error at once (nothing waits for a completion).
TEST_F(TrackerRoutes, NoResponseFramesTakeTheirOwnDestinationAndMayBeRefused) {
    auto sid = tracker.submit_no_response(read_code, read_params, to(other_plc, 5));
    ASSERT_TRUE(sid.has_value());
    EXPECT_EQ(wire.frames.back()[0], 0x81);
    EXPECT_EQ(wire.frames.back()[4], 30);
    EXPECT_EQ(wire.lasts.back(), true);
    wire.refuse.insert(6);
    auto refused = tracker.submit_no_response(read_code, read_params, to(other_plc, 6));
    ASSERT_FALSE(refused.has_value());
    EXPECT_EQ(refused.error(), make_error_code(ClientError::not_connected));
    EXPECT_EQ(wire.frames.size(), 1u);
    EXPECT_EQ(tracker.stats().refused, 1u);
}

// finsd's instructions turn the clean-SID rest off (set_rest_clean_ids(false)): a SID
// answered at once is used again as soon as the least-recently-used order reaches it;
// with the rest (fins::Client's default) the 257th request at the same instant waits.
TEST_F(TrackerRoutes, WithoutTheCleanRestAnAnsweredSidIsReusedAtOnce) {
    const auto cycle = [&](RequestTracker& t, RouteWire& w) {
        for (int i = 0; i < 257; ++i) {
            Outcome o;
            ASSERT_TRUE(t.submit(read_code, read_params, {}, o.callback(), t0).has_value());
            if (t.waiting() > 0) return;
            const auto& f = w.frames.back();
            ASSERT_EQ(t.on_frame(answer(Bytes{f.data(), f.size()}), t0),
                      RequestTracker::Disposition::matched);
        }
    };
    cycle(tracker, wire);
    EXPECT_EQ(tracker.stats().waited_for_id, 1u);
    RouteWire other_wire;
    RequestTracker no_rest{other_wire};
    no_rest.set_rest_clean_ids(false);
    no_rest.link_up(plc, host, t0);
    cycle(no_rest, other_wire);
    EXPECT_EQ(no_rest.stats().waited_for_id, 0u);
    EXPECT_EQ(other_wire.frames.size(), 257u);
    EXPECT_EQ(other_wire.frames.back()[9], other_wire.frames.front()[9]);
}

}  // namespace
}  // namespace fins::test
