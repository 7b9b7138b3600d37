// The bridge's command path in process (no broker, no PLC): every Sparkplug command the bridge
// refuses is logged and counted and ends nothing (it used to abort fins-bridge: a parse result
// with no write was dereferenced as one), and the failure boundary around each MQTT message
// turns an exception into a refusal, a log line and a count.
#include <gtest/gtest.h>

#include <boost/asio/io_context.hpp>

#include "bridge/bridge.hpp"
#include "bridge/bridge_test_support.hpp"
#include "bridge/json_payload.hpp"
#include "bridge/sparkplug/sparkplug_payload.hpp"

namespace fb = fins::bridge;
namespace sp = fins::bridge::sparkplug;
namespace pb = finskit::sparkplug::pb;

namespace {

fb::BridgeConfig config() {
    return fb::test::parse_ok(
        "[bridge]\npayload = \"sparkplug\"\n[mqtt]\ntopic_prefix = \"plant\"\n" +
        fb::test::one_group(R"({ name = "speed", address = "D100", type = "int16" },
                               { name = "temp", address = "D200", type = "float", writable = true })"));
}

// A format that records the answers and rejections the bridge hands back, and throws in
// parse() for the payload "throw" (the failure boundary's test hook for a parse that fails).
class Recording final : public fb::PayloadFormat {
  public:
    explicit Recording(std::unique_ptr<fb::PayloadFormat> inner) : inner_(std::move(inner)) {}
    std::vector<std::string> subscriptions() const override { return inner_->subscriptions(); }
    fb::Message bridge_status(bool online) const override { return inner_->bridge_status(online); }
    void connected(const fb::Sink& out) override { inner_->connected(out); }
    void values(const fb::GroupSample& s, const fb::Sink& out) override { inner_->values(s, out); }
    void status(const fb::PlcStatus& s, const fb::Sink& out) override { inner_->status(s, out); }
    void write_response(const fb::Plc& plc, const fb::WriteResponse& r,
                        const fb::Sink& out) override {
        answers.emplace_back(plc.name, r);
        inner_->write_response(plc, r, out);
    }
    std::optional<fb::ParsedCommand> parse(std::string_view topic, std::string_view payload,
                                           bool retained) override {
        if (payload == "throw") throw std::runtime_error("parse failed");
        return inner_->parse(topic, payload, retained);
    }
    void rejected(std::string_view topic, std::string_view reason) override {
        rejections.emplace_back(std::string(topic), std::string(reason));
        inner_->rejected(topic, reason);
    }
    std::uint64_t rejected_commands() const override { return inner_->rejected_commands(); }

    std::vector<std::pair<std::string, fb::WriteResponse>> answers;
    std::vector<std::pair<std::string, std::string>> rejections;

  private:
    std::unique_ptr<fb::PayloadFormat> inner_;
};

// Owns everything; its membership handling throws for the topic "boom".
class Throwing final : public fb::Ownership {
  public:
    bool owns(std::string_view) const override { return true; }
    bool on_message(std::string_view topic, std::string_view) override {
        if (topic == "boom") throw std::runtime_error("membership failed");
        return false;
    }
};

struct Harness {
    asio::io_context io;
    fb::BridgeConfig cfg = config();
    Recording* format = nullptr;
    std::unique_ptr<fb::Bridge> bridge;

    explicit Harness(bool sparkplug = true) {
        std::unique_ptr<fb::PayloadFormat> inner;
        if (sparkplug)
            inner = std::make_unique<sp::SparkplugPayload>(cfg, "plant");
        else
            inner = std::make_unique<fb::JsonPayload>("plant", "test");
        auto f = std::make_unique<Recording>(std::move(inner));
        format = f.get();
        bridge = std::make_unique<fb::Bridge>(io, cfg, std::move(f), std::make_unique<Throwing>());
    }
    // One message through the bridge as the MQTT thread hands it in.
    void send(const std::string& topic, const std::string& payload, bool retained = false) {
        bridge->incoming(topic, payload, retained);
        io.restart();
        while (io.poll() > 0) {
        }
    }
    // The PLC answered a whole cycle: its DBIRTH, the device attached for DCMDs.
    void first_values() {
        std::vector<fb::TagSample> tags(2);
        bridge->status_changed({&cfg.plcs[0], true, "", 1});
        bridge->group_done({&cfg.plcs[0], &cfg.plcs[0].groups[0], tags, 2, true});
    }
};

std::string metric_payload(const std::function<void(pb::Payload::Metric&)>& set) {
    pb::Payload p;
    p.set_timestamp(1);
    set(*p.add_metrics());
    return p.SerializeAsString();
}

const std::string dcmd = "spBv1.0/plant/DCMD/test/p";
const std::string ncmd = "spBv1.0/plant/NCMD/test";

}  // namespace

TEST(SparkplugCommand, EveryRefusedCommandIsLoggedAndCountedAndEndsNothing) {
    Harness h;
    h.first_values();
    const auto temp = [](float v) {
        return metric_payload([v](auto& m) {
            m.set_name("g/temp");
            m.set_datatype(pb::Float);
            m.set_float_value(v);
        });
    };
    struct Case {
        const char* what;
        std::string topic;
        std::string payload;
        bool retained = false;
    };
    const std::vector<Case> cases{
        {"read-only metric", dcmd, metric_payload([](auto& m) {
             m.set_name("g/speed");
             m.set_int_value(3);
         })},
        {"unknown metric", dcmd, metric_payload([](auto& m) {
             m.set_name("g/nope");
             m.set_int_value(3);
         })},
        {"unknown alias", dcmd, metric_payload([](auto& m) { m.set_alias(12345); })},
        {"wrong value field", dcmd, metric_payload([](auto& m) {
             m.set_name("g/temp");
             m.set_int_value(3);
         })},
        {"no metric at all", dcmd, pb::Payload().SerializeAsString()},
        {"unknown device", "spBv1.0/plant/DCMD/test/nope", temp(1)},
        {"NCMD Rebirth = false", ncmd, metric_payload([](auto& m) {
             m.set_name("Node Control/Rebirth");
             m.set_boolean_value(false);
         })},
        {"unknown node metric", ncmd, metric_payload([](auto& m) {
             m.set_name("Node Control/Reboot");
             m.set_boolean_value(true);
         })},
        {"NCMD not protobuf", ncmd, "\xff\xff\xff"},
        {"DCMD not protobuf", dcmd, "\xff\xff\xff"},
        {"retained DCMD", dcmd, temp(1), true},
        {"retained NCMD", ncmd, "\xff", true},
        // Executed, and refused by the write path: the PLC is not polled here.
        {"PLC not polled", dcmd, temp(2)},
    };
    std::uint64_t expected = 0;
    for (const auto& c : cases) {
        h.send(c.topic, c.payload, c.retained);
        ++expected;
        EXPECT_EQ(h.format->rejected_commands(), expected) << c.what;
    }
    EXPECT_EQ(h.bridge->failed_commands(), 0U);
    EXPECT_TRUE(h.format->answers.size() == 1 && !h.format->answers[0].second.ok);

    // The PLC goes offline: its device is dead, a DCMD for it is refused before the write path.
    h.bridge->status_changed({&h.cfg.plcs[0], false, "timeout", 3});
    h.send(dcmd, temp(3));
    EXPECT_EQ(h.format->rejected_commands(), expected + 1);
    ASSERT_FALSE(h.format->rejections.empty());
    EXPECT_EQ(h.format->rejections.back().second,
              "device p is not published by this Edge Node");
    EXPECT_EQ(h.format->answers.size(), 1U);  // nothing reached the write path
}

TEST(SparkplugCommand, OneMetricPerDcmdTheOthersAreRejected) {
    Harness h;
    h.first_values();
    pb::Payload p;
    for (const char* name : {"g/speed", "g/temp", "g/temp"}) {
        auto* m = p.add_metrics();
        m->set_name(name);
        m->set_float_value(1.0F);
    }
    h.send(dcmd, p.SerializeAsString());
    // g/speed (read-only) and the second g/temp rejected by the format; the first g/temp
    // executed, and refused by the write path (not polled here).
    ASSERT_EQ(h.format->answers.size(), 1U);
    EXPECT_EQ(h.format->answers[0].second.error, "this instance does not poll the PLC");
    EXPECT_EQ(h.format->rejected_commands(), 3U);
}

TEST(SparkplugCommand, AFailureInHandlingAMessageIsARefusalNotAnEnd) {
    Harness h;
    h.first_values();
    std::function<void()> thrower;
    h.bridge->set_command_hook([&](const fb::ParsedCommand&) {
        if (thrower) thrower();
    });
    // The parse throws: nothing understood, nothing to answer; counted.
    h.send(dcmd, "throw");
    EXPECT_EQ(h.bridge->failed_commands(), 1U);
    EXPECT_EQ(h.format->rejected_commands(), 0U);
    // Membership handling throws (any topic, not only commands).
    h.send("boom", "x");
    EXPECT_EQ(h.bridge->failed_commands(), 2U);
    // A DCMD write, an NCMD Rebirth and a rejected command whose handling throws (out of
    // memory, or anything else): each is a logged and counted refusal.
    thrower = [] { throw std::bad_alloc(); };
    h.send(dcmd, metric_payload([](auto& m) {
               m.set_name("g/temp");
               m.set_float_value(1.0F);
           }));
    ASSERT_EQ(h.format->answers.size(), 1U);
    EXPECT_FALSE(h.format->answers[0].second.ok);
    EXPECT_EQ(h.format->answers[0].second.error.rfind("internal error: ", 0), 0U);
    thrower = [] { throw 42; };
    h.send(ncmd, metric_payload([](auto& m) {
               m.set_name("Node Control/Rebirth");
               m.set_boolean_value(true);
           }));
    h.send(ncmd, "\xff");
    EXPECT_EQ(h.bridge->failed_commands(), 5U);
    EXPECT_EQ(h.format->rejected_commands(), 3U);
    ASSERT_EQ(h.format->rejections.size(), 2U);
    EXPECT_EQ(h.format->rejections[0].second, "internal error: unknown exception");
    // Nothing throws any more: commands are handled again.
    thrower = nullptr;
    h.send(ncmd, "\xff");
    EXPECT_EQ(h.format->rejected_commands(), 4U);
    EXPECT_EQ(h.bridge->failed_commands(), 5U);
}

TEST(SparkplugCommand, AJsonWriteWhoseHandlingFailsIsAnsweredOkFalse) {
    Harness h(false);
    h.bridge->set_command_hook([](const fb::ParsedCommand& c) {
        if (const auto* w = std::get_if<fb::WriteCommand>(&c); w && w->id == "\"bad\"")  // the id's JSON text
            throw std::runtime_error("boom");
    });
    h.send("plant/p/write", R"({"id":"bad","tag":"temp","value":1})");
    ASSERT_EQ(h.format->answers.size(), 1U);
    EXPECT_EQ(h.format->answers[0].first, "p");
    EXPECT_EQ(h.format->answers[0].second.id, "\"bad\"");
    EXPECT_FALSE(h.format->answers[0].second.ok);
    EXPECT_EQ(h.format->answers[0].second.error, "internal error: boom");
    // The id is remembered with that answer: a repeat gets the same, and is not executed.
    h.send("plant/p/write", R"({"id":"bad","tag":"temp","value":1})");
    EXPECT_EQ(h.bridge->failed_commands(), 2U);
    ASSERT_EQ(h.format->answers.size(), 2U);
    EXPECT_EQ(h.format->answers[1].second.error, "internal error: boom");
    // A parse that throws: counted, nothing to answer; then a good refusal is answered again.
    h.send("plant/p/write", "throw");
    EXPECT_EQ(h.bridge->failed_commands(), 3U);
    EXPECT_EQ(h.format->answers.size(), 2U);
    h.send("plant/p/write", "nope");
    ASSERT_EQ(h.format->answers.size(), 3U);
    EXPECT_EQ(h.format->answers[2].second.error, "the command is not a JSON object");
}
