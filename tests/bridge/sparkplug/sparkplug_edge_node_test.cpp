// The Edge Node state machine against Sparkplug 3.0's rules, with no broker: every message it
// produces is decoded back with the generated protobuf code and checked field by field.
#include <gtest/gtest.h>

#include <set>

#include "bridge/sparkplug/edge_node.hpp"

namespace sp = fins::bridge::sparkplug;
namespace pb = finskit::sparkplug::pb;

namespace {

pb::Payload decode(const sp::Message& m) {
    pb::Payload p;
    EXPECT_TRUE(p.ParseFromString(m.payload)) << m.topic;
    return p;
}

const pb::Payload::Metric* metric(const pb::Payload& p, std::string_view name) {
    for (const auto& m : p.metrics())
        if (m.name() == name) return &m;
    return nullptr;
}

void define_devices(sp::EdgeNode& node) {
    node.define_device("press1", {{"fast/speed", pb::Int16, false},
                                  {"fast/run", pb::Boolean, false},
                                  {"fast/temp", pb::Float, true}});
    node.define_device("press2", {{"slow/count", pb::UInt32, true}});
}

}  // namespace

TEST(SparkplugEdgeNode, WillIsNdeathWithBdSeqThatStepsPerConnectAndWraps) {
    sp::EdgeNode node("plant", "edge-1");
    const auto first = node.next_will(1000);
    EXPECT_EQ(first.topic, "spBv1.0/plant/NDEATH/edge-1");
    EXPECT_EQ(first.qos, 1);
    EXPECT_FALSE(first.retain);
    auto p = decode(first);
    EXPECT_FALSE(p.has_seq());  // NDEATH carries no seq
    ASSERT_NE(metric(p, "bdSeq"), nullptr);
    EXPECT_EQ(metric(p, "bdSeq")->datatype(), static_cast<unsigned>(pb::Int64));
    EXPECT_EQ(metric(p, "bdSeq")->long_value(), 0U);
    for (int i = 1; i < 256; ++i)
        EXPECT_EQ(decode(node.next_will(1000)).metrics(0).long_value(), static_cast<unsigned>(i));
    EXPECT_EQ(decode(node.next_will(1000)).metrics(0).long_value(), 0U);  // 255 -> 0
}

TEST(SparkplugEdgeNode, BirthIsNbirthThenDbirthOfAttachedDevicesWithNamesAliasesAndTypes) {
    sp::EdgeNode node("plant", "edge-1");
    define_devices(node);
    (void)node.next_will(5);
    (void)node.next_will(5);  // second connection: bdSeq 1
    std::vector<sp::Message> out;
    node.attach("press1", 10, out);
    EXPECT_TRUE(out.empty());  // nothing before the NBIRTH
    node.birth(20, out);
    ASSERT_EQ(out.size(), 2U);  // press2 is not attached
    EXPECT_EQ(out[0].topic, "spBv1.0/plant/NBIRTH/edge-1");
    EXPECT_EQ(out[1].topic, "spBv1.0/plant/DBIRTH/edge-1/press1");
    for (const auto& m : out) {
        EXPECT_EQ(m.qos, 0);
        EXPECT_FALSE(m.retain);
    }
    const auto nbirth = decode(out[0]);
    EXPECT_EQ(nbirth.seq(), 0U);
    EXPECT_EQ(nbirth.timestamp(), 20U);
    ASSERT_NE(metric(nbirth, "bdSeq"), nullptr);
    EXPECT_EQ(metric(nbirth, "bdSeq")->long_value(), 1U);  // the Will's
    const auto* rebirth = metric(nbirth, "Node Control/Rebirth");
    ASSERT_NE(rebirth, nullptr);
    EXPECT_EQ(rebirth->datatype(), static_cast<unsigned>(pb::Boolean));
    EXPECT_FALSE(rebirth->boolean_value());
    EXPECT_TRUE(rebirth->has_boolean_value());
    EXPECT_FALSE(rebirth->has_alias());

    const auto dbirth = decode(out[1]);
    EXPECT_EQ(dbirth.seq(), 1U);
    ASSERT_EQ(dbirth.metrics_size(), 3);
    std::set<std::uint64_t> aliases;
    for (const auto& m : dbirth.metrics()) {
        EXPECT_TRUE(m.has_name());
        EXPECT_TRUE(m.has_alias());
        EXPECT_TRUE(m.has_datatype());
        EXPECT_TRUE(m.is_null());  // nothing read yet: null, not a made-up 0
        aliases.insert(m.alias());
    }
    EXPECT_EQ(aliases.size(), 3U);
    EXPECT_EQ(dbirth.metrics(0).name(), "fast/speed");
    EXPECT_EQ(dbirth.metrics(0).datatype(), static_cast<unsigned>(pb::Int16));
    EXPECT_EQ(dbirth.metrics(2).datatype(), static_cast<unsigned>(pb::Float));
}

TEST(SparkplugEdgeNode, DdataCarriesAliasesOnlyAndSeqWrapsAfter255) {
    sp::EdgeNode node("plant", "edge-1");
    define_devices(node);
    (void)node.next_will(0);
    std::vector<sp::Message> out;
    node.attach("press1", 0, out);
    node.birth(1, out);
    const auto dbirth = decode(out[1]);
    const std::uint64_t alias_speed = dbirth.metrics(0).alias();
    out.clear();
    std::uint64_t expected = 2;
    for (int i = 0; i < 600; ++i) {
        const sp::MetricUpdate u{0, std::int64_t{-i}, 100U + static_cast<unsigned>(i)};
        node.data("press1", std::span(&u, 1), 200, out);
        ASSERT_EQ(out.size(), 1U);
        EXPECT_EQ(out[0].topic, "spBv1.0/plant/DDATA/edge-1/press1");
        const auto p = decode(out[0]);
        ASSERT_EQ(p.seq(), expected) << i;
        expected = (expected + 1) % 256;
        ASSERT_EQ(p.metrics_size(), 1);
        EXPECT_FALSE(p.metrics(0).has_name());
        EXPECT_FALSE(p.metrics(0).has_datatype());
        EXPECT_EQ(p.metrics(0).alias(), alias_speed);
        EXPECT_EQ(p.metrics(0).timestamp(), 100U + static_cast<unsigned>(i));
        EXPECT_EQ(static_cast<std::int16_t>(p.metrics(0).int_value()),
                  static_cast<std::int16_t>(-i));
        out.clear();
    }
    // A device that is not attached, and nothing at all: no message.
    const sp::MetricUpdate u{0, std::uint64_t{1}, 1};
    node.data("press2", std::span(&u, 1), 1, out);
    node.data("press1", {}, 1, out);
    EXPECT_TRUE(out.empty());
}

TEST(SparkplugEdgeNode, RebirthRestartsSeqAtZeroWithSameBdSeqAndLastValues) {
    sp::EdgeNode node("plant", "edge-1");
    define_devices(node);
    (void)node.next_will(0);
    std::vector<sp::Message> out;
    node.attach("press1", 0, out);
    node.birth(1, out);
    const sp::MetricUpdate u{2, 21.5, 50};
    node.data("press1", std::span(&u, 1), 60, out);
    out.clear();
    node.birth(70, out);
    ASSERT_EQ(out.size(), 2U);
    EXPECT_EQ(decode(out[0]).seq(), 0U);
    EXPECT_EQ(metric(decode(out[0]), "bdSeq")->long_value(), 0U);
    const auto dbirth = decode(out[1]);
    EXPECT_EQ(dbirth.seq(), 1U);
    EXPECT_FALSE(dbirth.metrics(2).is_null());
    EXPECT_FLOAT_EQ(dbirth.metrics(2).float_value(), 21.5F);
    EXPECT_EQ(dbirth.metrics(2).timestamp(), 50U);
}

TEST(SparkplugEdgeNode, AttachAndDetachAfterBirthAreDbirthAndDdeath) {
    sp::EdgeNode node("plant", "edge-1");
    define_devices(node);
    (void)node.next_will(0);
    std::vector<sp::Message> out;
    node.birth(1, out);
    ASSERT_EQ(out.size(), 1U);  // NBIRTH only
    out.clear();
    node.attach("press2", 2, out);
    node.attach("press2", 2, out);  // twice: one DBIRTH
    node.detach("press2", 3, out);
    node.detach("press2", 3, out);
    node.attach("nope", 3, out);
    ASSERT_EQ(out.size(), 2U);
    EXPECT_EQ(out[0].topic, "spBv1.0/plant/DBIRTH/edge-1/press2");
    EXPECT_EQ(out[1].topic, "spBv1.0/plant/DDEATH/edge-1/press2");
    EXPECT_EQ(decode(out[0]).seq(), 1U);
    const auto ddeath = decode(out[1]);
    EXPECT_EQ(ddeath.seq(), 2U);  // DDEATH carries a seq
    EXPECT_EQ(ddeath.timestamp(), 3U);
    // After a lost connection nothing goes out until the next birth.
    node.connection_lost();
    out.clear();
    node.attach("press1", 4, out);
    EXPECT_TRUE(out.empty());
}

TEST(SparkplugEdgeNode, NcmdRebirthIsRecognisedAndOtherNodeCommandsAreErrors) {
    sp::EdgeNode node("plant", "edge-1");
    define_devices(node);
    std::vector<sp::Command> cmds;
    pb::Payload p;
    auto* m = p.add_metrics();
    m->set_name("Node Control/Rebirth");
    m->set_boolean_value(true);
    node.on_command("spBv1.0/plant/NCMD/edge-1", p.SerializeAsString(), cmds);
    ASSERT_EQ(cmds.size(), 1U);
    EXPECT_TRUE(std::holds_alternative<sp::Rebirth>(cmds[0]));
    cmds.clear();
    m->set_boolean_value(false);
    node.on_command("spBv1.0/plant/NCMD/edge-1", p.SerializeAsString(), cmds);
    m->set_name("Node Control/Reboot");
    m->set_boolean_value(true);
    node.on_command("spBv1.0/plant/NCMD/edge-1", p.SerializeAsString(), cmds);
    node.on_command("spBv1.0/plant/NCMD/edge-1", "\xff\xff\xff", cmds);
    node.on_command("spBv1.0/other/NCMD/edge-1", p.SerializeAsString(), cmds);
    ASSERT_EQ(cmds.size(), 4U);
    for (const auto& c : cmds)
        EXPECT_TRUE(std::holds_alternative<sp::CommandError>(c));
}

TEST(SparkplugEdgeNode, DcmdBecomesTypedWritesByAliasOrNameAndRefusesTheRest) {
    sp::EdgeNode node("plant", "edge-1");
    define_devices(node);
    (void)node.next_will(0);
    std::vector<sp::Message> out;
    node.attach("press1", 0, out);
    node.birth(1, out);
    const auto dbirth = decode(out[1]);
    std::vector<sp::Command> cmds;
    pb::Payload p;
    p.set_timestamp(5);
    auto* by_alias = p.add_metrics();
    by_alias->set_alias(dbirth.metrics(2).alias());
    by_alias->set_float_value(1.5F);
    auto* by_name = p.add_metrics();
    by_name->set_name("fast/temp");
    by_name->set_float_value(-3.25F);
    auto* read_only = p.add_metrics();
    read_only->set_name("fast/speed");
    read_only->set_int_value(5);
    auto* wrong_type = p.add_metrics();
    wrong_type->set_name("fast/temp");
    wrong_type->set_string_value("hot");
    auto* unknown = p.add_metrics();
    unknown->set_alias(999);
    unknown->set_float_value(1);
    node.on_command("spBv1.0/plant/DCMD/edge-1/press1", p.SerializeAsString(), cmds);
    ASSERT_EQ(cmds.size(), 5U);
    const auto* w0 = std::get_if<sp::DeviceWrite>(&cmds[0]);
    const auto* w1 = std::get_if<sp::DeviceWrite>(&cmds[1]);
    ASSERT_NE(w0, nullptr);
    ASSERT_NE(w1, nullptr);
    EXPECT_EQ(w0->device, "press1");
    EXPECT_EQ(w0->index, 2U);
    EXPECT_EQ(w0->metric, "fast/temp");
    EXPECT_EQ(std::get<double>(w0->value), 1.5);
    EXPECT_EQ(std::get<double>(w1->value), -3.25);
    EXPECT_NE(std::get<sp::CommandError>(cmds[2]).reason.find("not writable"), std::string::npos);
    EXPECT_NE(std::get<sp::CommandError>(cmds[3]).reason.find("float_value"), std::string::npos);
    EXPECT_NE(std::get<sp::CommandError>(cmds[4]).reason.find("alias 999"), std::string::npos);

    // A device this node does not publish (another instance owns it) and an unknown one.
    cmds.clear();
    node.on_command("spBv1.0/plant/DCMD/edge-1/press2", p.SerializeAsString(), cmds);
    node.on_command("spBv1.0/plant/DCMD/edge-1/press9", p.SerializeAsString(), cmds);
    ASSERT_EQ(cmds.size(), 2U);
    EXPECT_NE(std::get<sp::CommandError>(cmds[0]).reason.find("not published"), std::string::npos);
    EXPECT_NE(std::get<sp::CommandError>(cmds[1]).reason.find("no device"), std::string::npos);
}

TEST(SparkplugEdgeNode, DeathRepeatsTheWillsBdSeq) {
    sp::EdgeNode node("g", "n");
    (void)node.next_will(0);
    (void)node.next_will(0);
    const auto d = node.death(9);
    EXPECT_EQ(d.topic, "spBv1.0/g/NDEATH/n");
    EXPECT_EQ(decode(d).metrics(0).long_value(), 1U);
}

TEST(SparkplugTopic, ParsesFourAndFiveLevelsOnly) {
    auto t = sp::parse_topic("spBv1.0/g/DCMD/n/d");
    ASSERT_TRUE(t);
    EXPECT_EQ(t->group_id, "g");
    EXPECT_EQ(t->verb, "DCMD");
    EXPECT_EQ(t->edge_node_id, "n");
    EXPECT_EQ(t->device_id, "d");
    t = sp::parse_topic("spBv1.0/g/NCMD/n");
    ASSERT_TRUE(t);
    EXPECT_TRUE(t->device_id.empty());
    EXPECT_FALSE(sp::parse_topic("spBv1.0/g/NCMD"));
    EXPECT_FALSE(sp::parse_topic("spBv1.0/g/DCMD/n/d/x"));
    EXPECT_FALSE(sp::parse_topic("spAv1.0/g/NCMD/n"));
    EXPECT_FALSE(sp::parse_topic("spBv1.0//NCMD/n"));
    EXPECT_FALSE(sp::parse_topic("spBv1.0/g/DCMD/n/"));
    EXPECT_FALSE(sp::parse_topic(""));
}
