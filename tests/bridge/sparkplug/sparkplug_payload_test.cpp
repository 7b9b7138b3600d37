// The Sparkplug format behind the bridge's PayloadFormat seam: a config becomes an Edge Node
// with one device per PLC, samples become DBIRTH/DDATA, DCMD becomes the bridge's own write
// command (checked and executed by the same path as JSON writes).
#include <gtest/gtest.h>

#include "bridge/bridge_test_support.hpp"
#include "bridge/sparkplug/sparkplug_payload.hpp"
#include "fins/values.hpp"

namespace fb = fins::bridge;
namespace sp = fins::bridge::sparkplug;
namespace pb = finskit::sparkplug::pb;

namespace {

fb::BridgeConfig config() {
    auto c = fb::test::parse_ok(
        "[bridge]\npayload = \"sparkplug\"\n" +
        fb::test::one_group(R"({ name = "speed", address = "D100", type = "int16" },
                               { name = "temp", address = "D200", type = "float", writable = true })"));
    return c;
}

std::vector<fb::Message> collect(const std::function<void(const fb::Sink&)>& f) {
    std::vector<fb::Message> out;
    f([&](fb::Message&& m) { out.push_back(std::move(m)); });
    return out;
}

}  // namespace

TEST(SparkplugPayload, TagValuesBecomeMetricValuesOfTheirDatatype) {
    fb::TagValue v;
    v.words[0] = 0xFFFE;
    EXPECT_EQ(std::get<std::int64_t>(sp::to_metric_value(fb::TagType::int16, v)), -2);
    EXPECT_EQ(std::get<std::uint64_t>(sp::to_metric_value(fb::TagType::uint16, v)), 0xFFFEU);
    const auto f = fins::float_to_words(1.5F);
    v.words = {f[0], f[1], 0, 0};
    EXPECT_EQ(std::get<double>(sp::to_metric_value(fb::TagType::float32, v)), 1.5);
    v.words = {0x1234, 0, 0, 0};
    EXPECT_EQ(std::get<std::uint64_t>(sp::to_metric_value(fb::TagType::bcd, v)), 1234U);
    v.words = {0x12AB, 0, 0, 0};  // not BCD: no number at all
    EXPECT_TRUE(std::holds_alternative<std::monostate>(sp::to_metric_value(fb::TagType::bcd, v)));
    EXPECT_EQ(sp::datatype_of(fb::TagType::float64), pb::Double);
    EXPECT_EQ(sp::datatype_of(fb::TagType::bits), pb::Boolean);
}

TEST(SparkplugPayload, BirthThenDataOfAPolledGroup) {
    const auto c = config();
    sp::SparkplugPayload fmt(c, "plant");
    const auto will = fmt.session_will();
    EXPECT_EQ(will.topic, "spBv1.0/plant/NDEATH/test");
    EXPECT_EQ(fmt.subscriptions(),
              (std::vector<std::string>{"spBv1.0/plant/NCMD/test", "spBv1.0/plant/DCMD/test/+"}));
    auto out = collect([&](const fb::Sink& s) { fmt.connected(s); });
    ASSERT_EQ(out.size(), 1U);
    EXPECT_EQ(out[0].topic, "spBv1.0/plant/NBIRTH/test");

    std::vector<fb::TagSample> tags(2);
    tags[0].value.words[0] = 7;
    tags[0].changed = true;
    tags[1].error = std::make_error_code(std::errc::timed_out);
    fb::GroupSample s{&c.plcs[0], &c.plcs[0].groups[0], tags, 1000, false};
    out = collect([&](const fb::Sink& sink) { fmt.values(s, sink); });
    ASSERT_EQ(out.size(), 1U);  // the device's DBIRTH (first answer), carrying the values
    EXPECT_EQ(out[0].topic, "spBv1.0/plant/DBIRTH/test/p");
    pb::Payload dbirth;
    ASSERT_TRUE(dbirth.ParseFromString(out[0].payload));
    ASSERT_EQ(dbirth.metrics_size(), 2);
    EXPECT_EQ(dbirth.metrics(0).name(), "g/speed");
    EXPECT_EQ(dbirth.metrics(1).name(), "g/temp");
    EXPECT_FALSE(dbirth.metrics(0).is_null());
    EXPECT_EQ(dbirth.metrics(0).int_value(), 7U);
    EXPECT_EQ(dbirth.metrics(0).timestamp(), 1000U);
    EXPECT_TRUE(dbirth.metrics(1).is_null());  // the failed read: null, Quality BAD
    tags[0].value.words[0] = 8;
    out = collect([&](const fb::Sink& sink) { fmt.values(s, sink); });
    ASSERT_EQ(out.size(), 1U);
    EXPECT_EQ(out[0].topic, "spBv1.0/plant/DDATA/test/p");
    pb::Payload ddata;
    ASSERT_TRUE(ddata.ParseFromString(out[0].payload));
    ASSERT_EQ(ddata.metrics_size(), 2);
    EXPECT_EQ(ddata.metrics(0).int_value(), 8U);
    EXPECT_TRUE(ddata.metrics(1).is_null());

    // The PLC goes offline: DDEATH; another instance takes it: nothing more.
    out = collect([&](const fb::Sink& sink) {
        fmt.status({&c.plcs[0], false, "timeout", 2000}, sink);
    });
    ASSERT_EQ(out.size(), 1U);
    EXPECT_EQ(out[0].topic, "spBv1.0/plant/DDEATH/test/p");
    out = collect([&](const fb::Sink& sink) { fmt.released(c.plcs[0], sink); });
    EXPECT_TRUE(out.empty());
}

TEST(SparkplugPayload, DcmdBecomesTheBridgesWriteCommandAndRetainedOnesAreRefused) {
    const auto c = config();
    sp::SparkplugPayload fmt(c, "plant");
    (void)fmt.session_will();
    (void)collect([&](const fb::Sink& s) { fmt.connected(s); });
    (void)collect([&](const fb::Sink& s) { fmt.status({&c.plcs[0], true, "", 5}, s); });
    std::vector<fb::TagSample> tags(2);
    (void)collect([&](const fb::Sink& s) {
        fmt.values({&c.plcs[0], &c.plcs[0].groups[0], tags, 6, true}, s);
    });
    ASSERT_TRUE(fmt.node().attached("p"));
    pb::Payload p;
    p.set_timestamp(10);
    auto* m = p.add_metrics();
    m->set_name("g/temp");
    m->set_float_value(2.5F);
    const auto bytes = p.SerializeAsString();
    auto pc = fmt.parse("spBv1.0/plant/DCMD/test/p", bytes, false);
    ASSERT_TRUE(pc);
    const auto* w = std::get_if<fb::WriteCommand>(&*pc);
    ASSERT_TRUE(w);
    EXPECT_EQ(w->plc, "p");
    EXPECT_EQ(w->tag, "temp");
    EXPECT_EQ(w->value, nlohmann::json(2.5));
    EXPECT_FALSE(w->id.empty());
    const auto again = fmt.parse("spBv1.0/plant/DCMD/test/p", bytes, false);
    ASSERT_TRUE(again && std::holds_alternative<fb::WriteCommand>(*again));
    EXPECT_NE(std::get<fb::WriteCommand>(*again).id, w->id);  // each DCMD is its own command

    pc = fmt.parse("spBv1.0/plant/DCMD/test/p", bytes, true);
    ASSERT_TRUE(pc);
    EXPECT_TRUE(std::holds_alternative<fb::Rejected>(*pc));
    m->set_name("g/speed");  // not writable
    m->set_int_value(3);
    pc = fmt.parse("spBv1.0/plant/DCMD/test/p", p.SerializeAsString(), false);
    ASSERT_TRUE(pc);
    ASSERT_TRUE(std::holds_alternative<fb::Rejected>(*pc));
    EXPECT_EQ(std::get<fb::Rejected>(*pc).reason, "g/speed is not writable");
    // The format counts what the bridge hands back (Bridge::command), not what it parses.
    EXPECT_EQ(fmt.rejected_commands(), 0U);
    fmt.rejected("spBv1.0/plant/DCMD/test/p", "g/speed is not writable");
    EXPECT_EQ(fmt.rejected_commands(), 1U);
    EXPECT_FALSE(fmt.parse("finskit/p/write", "{}", false));  // not Sparkplug's
    EXPECT_FALSE(fmt.parse("spBv1.0/plant/DCMD/other/p", bytes, false));  // another Edge Node's
}

// A DBIRTH of nulls with Quality BAD told host applications the PLC's values were bad when
// they were only not read yet: the DBIRTH waits for the first values of every group, at
// start and when the PLC comes back after being offline.
TEST(SparkplugPayload, DbirthWaitsForTheFirstValuesOfEveryGroup) {
    const auto c = fb::test::parse_ok(
        "[bridge]\npayload = \"sparkplug\"\n[[plc]]\nname = \"p\"\nhost = \"127.0.0.1\"\n"
        "[[plc.group]]\nname = \"a\"\ntags = [ { name = \"x\", address = \"D0\", type = "
        "\"int16\" } ]\n"
        "[[plc.group]]\nname = \"b\"\ntags = [ { name = \"y\", address = \"D1\", type = "
        "\"uint16\" } ]\n");
    sp::SparkplugPayload fmt(c, "plant");
    (void)fmt.session_will();
    (void)collect([&](const fb::Sink& s) { fmt.connected(s); });
    const auto& plc = c.plcs[0];
    std::vector<fb::TagSample> x(1);
    std::vector<fb::TagSample> y(1);
    const auto cycle = [&](std::uint16_t vx, std::uint16_t vy, std::int64_t ts) {
        x[0].value.words[0] = vx;
        y[0].value.words[0] = vy;
        auto out = collect([&](const fb::Sink& s) {
            fmt.values({&plc, &plc.groups[0], x, ts, true}, s);
        });
        EXPECT_TRUE(out.empty()) << "published before every group had values";
        return collect([&](const fb::Sink& s) {
            fmt.values({&plc, &plc.groups[1], y, ts + 1, true}, s);
        });
    };
    for (int round = 0; round < 2; ++round) {
        // Online (at start; then back after being offline): nothing yet.
        auto out = collect([&](const fb::Sink& s) { fmt.status({&plc, true, "", 10}, s); });
        EXPECT_TRUE(out.empty());
        out = cycle(static_cast<std::uint16_t>(5 + round), 6, 20);
        ASSERT_EQ(out.size(), 1U);
        EXPECT_EQ(out[0].topic, "spBv1.0/plant/DBIRTH/test/p");
        pb::Payload dbirth;
        ASSERT_TRUE(dbirth.ParseFromString(out[0].payload));
        ASSERT_EQ(dbirth.metrics_size(), 2);
        EXPECT_FALSE(dbirth.metrics(0).is_null());
        EXPECT_FALSE(dbirth.metrics(1).is_null());
        EXPECT_EQ(dbirth.metrics(0).int_value(), 5U + static_cast<unsigned>(round));
        EXPECT_EQ(dbirth.metrics(1).int_value(), 6U);
        out = collect([&](const fb::Sink& s) { fmt.status({&plc, false, "timeout", 30}, s); });
        ASSERT_EQ(out.size(), 1U);
        EXPECT_EQ(out[0].topic, "spBv1.0/plant/DDEATH/test/p");
    }
}
