// fins-bridge in Sparkplug B mode against real mosquitto and finsd, with a subscriber that
// decodes every message with the generated protobuf code: the birth sequence, seq through
// 255 -> 0, rebirth on NCMD, a DCMD write executed once (counted on the wire), and the NDEATH
// Will with the NBIRTH's bdSeq after kill -9.
#include <gtest/gtest.h>

#include "bridge/cluster/processes.hpp"
#include "fins/values.hpp"
#include "integration/support/finsd_process.hpp"
#include "sparkplug_b.pb.h"

namespace tb = fins::test::bridge;
namespace pb = finskit::sparkplug::pb;
using namespace std::chrono_literals;

namespace {

struct Decoded {
    std::string verb;    // NBIRTH, DBIRTH, ...
    std::string device;  // DBIRTH/DDATA/DDEATH
    pb::Payload payload;
};

std::vector<Decoded> decode_all(const std::vector<tb::Received>& ms) {
    std::vector<Decoded> out;
    for (const auto& m : ms) {
        // spBv1.0/plant/VERB/edge-1[/device]
        std::vector<std::string> parts;
        std::size_t start = 0;
        while (true) {
            const auto slash = m.topic.find('/', start);
            parts.push_back(m.topic.substr(start, slash - start));
            if (slash == std::string::npos) break;
            start = slash + 1;
        }
        if (parts.size() < 4 || parts[0] != "spBv1.0" || parts[1] != "plant" ||
            parts[3] != "edge-1")
            continue;
        Decoded d;
        d.verb = parts[2];
        d.device = parts.size() > 4 ? parts[4] : "";
        // Every message of the bridge decodes; a command a test sent may be junk on purpose.
        if (!d.payload.ParseFromString(m.payload)) {
            EXPECT_TRUE(d.verb == "NCMD" || d.verb == "DCMD") << m.topic;
        }
        out.push_back(std::move(d));
    }
    return out;
}

std::int64_t bdseq_of(const pb::Payload& p) {
    for (const auto& m : p.metrics())
        if (m.name() == "bdSeq") return static_cast<std::int64_t>(m.long_value());
    return -1;
}

std::size_t count_verb(const std::vector<Decoded>& ds, const std::string& verb) {
    std::size_t n = 0;
    for (const auto& d : ds)
        n += d.verb == verb ? 1U : 0U;
    return n;
}

}  // namespace

TEST(SparkplugMqtt, BirthSequenceSeqWrapRebirthDcmdOnceAndNdeathOnKill) {
    if (tb::mosquitto_path().empty()) GTEST_SKIP() << "mosquitto is not installed";
    fins::test::ScratchDir dir("sparkplug");
    tb::Mosquitto broker(dir.path());
    ASSERT_TRUE(broker.started());
    fins::test::Finsd finsd({});
    ASSERT_TRUE(finsd.started());
    tb::CountingRelay relay(2, finsd.port());
    std::string conf =
        "[bridge]\ninstance = \"edge-1\"\npayload = \"sparkplug\"\nfailover_s = 9\n"
        "[mqtt]\nhost = \"127.0.0.1\"\nport = " +
        std::to_string(broker.port()) + "\ntopic_prefix = \"plant\"\n";
    for (int i = 0; i < 2; ++i) {
        conf += "[[plc]]\nname = \"press" + std::to_string(i + 1) +
                "\"\nhost = \"127.0.0.1\"\nport = " +
                std::to_string(relay.port(static_cast<std::size_t>(i))) + "\n";
        // publish = "always" at 20 ms: 100 DDATA a second, seq wraps within 3 s.
        conf +=
            "[[plc.group]]\nname = \"fast\"\ninterval_ms = 20\npublish = \"always\"\n"
            "tags = [ { name = \"speed\", address = \"D100\", type = \"int16\" },\n"
            "         { name = \"temp\", address = \"D200\", type = \"float\", writable = true } "
            "]\n";
    }
    const auto conf_path = dir.write("bridge.toml", conf);
    tb::Recorder rec(broker.port(), std::vector<std::string>{"spBv1.0/#"});
    tb::Child bridge({tb::bridge_path, "--config", conf_path}, dir.path() / "bridge.log");

    // 1. NBIRTH (seq 0), then DBIRTH of both devices, then DDATA; seq +1 mod 256 throughout.
    ASSERT_TRUE(
        rec.wait([](const auto& ms) { return count_verb(decode_all(ms), "DDATA") >= 300; }, 30s))
        << bridge.log();
    auto ds = decode_all(rec.messages());
    ASSERT_FALSE(ds.empty());
    ASSERT_EQ(ds[0].verb, "NBIRTH");
    EXPECT_EQ(ds[0].payload.seq(), 0U);
    const auto bdseq = bdseq_of(ds[0].payload);
    EXPECT_GE(bdseq, 0);
    std::set<std::string> born;
    bool wrapped = false;
    for (std::size_t i = 1; i < ds.size(); ++i) {
        ASSERT_TRUE(ds[i].payload.has_seq()) << ds[i].verb;
        ASSERT_EQ(ds[i].payload.seq(), (ds[i - 1].payload.seq() + 1) % 256) << "message " << i;
        wrapped = wrapped || ds[i].payload.seq() == 0;
        if (ds[i].verb == "DBIRTH") born.insert(ds[i].device);
        if (ds[i].verb == "DDATA") {
            ASSERT_TRUE(born.count(ds[i].device)) << "DDATA before DBIRTH";
        }
    }
    EXPECT_TRUE(wrapped);
    EXPECT_EQ(born, (std::set<std::string>{"press1", "press2"}));

    // 2. NCMD Node Control/Rebirth: a new NBIRTH with seq 0 and the same bdSeq, DBIRTHs after.
    pb::Payload ncmd;
    ncmd.set_timestamp(1);
    auto* r = ncmd.add_metrics();
    r->set_name("Node Control/Rebirth");
    r->set_datatype(pb::Boolean);
    r->set_boolean_value(true);
    const auto before = rec.count();
    rec.publish("spBv1.0/plant/NCMD/edge-1", ncmd.SerializeAsString(), 0);
    ASSERT_TRUE(rec.wait(
        [&](const auto& ms) {
            const auto all =
                decode_all({ms.begin() + static_cast<std::ptrdiff_t>(before), ms.end()});
            return count_verb(all, "DBIRTH") >= 2;
        },
        10s));
    auto after = rec.messages();
    ds = decode_all({after.begin() + static_cast<std::ptrdiff_t>(before), after.end()});
    std::size_t nbirth = 0;
    while (nbirth < ds.size() && ds[nbirth].verb != "NBIRTH")
        ++nbirth;
    ASSERT_LT(nbirth, ds.size());
    EXPECT_EQ(ds[nbirth].payload.seq(), 0U);
    EXPECT_EQ(bdseq_of(ds[nbirth].payload), bdseq);
    ASSERT_LT(nbirth + 2, ds.size());
    EXPECT_EQ(ds[nbirth + 1].verb, "DBIRTH");
    EXPECT_EQ(ds[nbirth + 2].verb, "DBIRTH");

    // 3. DCMD press1 fast/temp = 2.5: written once (one 01 02 on the wire), read back in DDATA.
    std::uint64_t temp_alias = 0;
    for (const auto& m : ds[nbirth + 1].payload.metrics())
        if (m.name() == "fast/temp") temp_alias = m.alias();
    const auto writes_before = relay.writes(0);
    pb::Payload dcmd;
    dcmd.set_timestamp(
        static_cast<std::uint64_t>(std::chrono::duration_cast<std::chrono::milliseconds>(
                                       std::chrono::system_clock::now().time_since_epoch())
                                       .count()));
    auto* w = dcmd.add_metrics();
    w->set_name("fast/temp");
    w->set_datatype(pb::Float);
    w->set_float_value(2.5F);
    rec.publish("spBv1.0/plant/DCMD/edge-1/press1", dcmd.SerializeAsString(), 0);
    auto client = finsd.client();
    bool written = false;
    for (int i = 0; i < 100 && !written; ++i) {
        const auto words = fins::test::words_of(*client, "D200", 2);
        written = words.size() == 2 && fins::words_to_float(words).value_or(0) == 2.5F;
        if (!written) std::this_thread::sleep_for(50ms);
    }
    EXPECT_TRUE(written);
    const auto seen = rec.count();
    ASSERT_TRUE(rec.wait(
        [&](const auto& ms) {
            for (const auto& d :
                 decode_all({ms.begin() + static_cast<std::ptrdiff_t>(seen), ms.end()}))
                if (d.verb == "DDATA" && d.device == "press1")
                    for (const auto& m : d.payload.metrics())
                        if (m.alias() == temp_alias && m.float_value() == 2.5F) return true;
            return false;
        },
        10s));
    std::this_thread::sleep_for(500ms);
    EXPECT_EQ(relay.writes(0) - writes_before, 1U);
    EXPECT_EQ(relay.writes(1), 0U);

    // 4. kill -9: the broker publishes the NDEATH Will with the NBIRTH's bdSeq.
    bridge.kill(SIGKILL);
    ASSERT_TRUE(
        rec.wait([](const auto& ms) { return count_verb(decode_all(ms), "NDEATH") >= 1; }, 30s));
    for (const auto& d : decode_all(rec.messages())) {
        if (d.verb != "NDEATH") continue;
        EXPECT_EQ(bdseq_of(d.payload), bdseq);
        EXPECT_FALSE(d.payload.has_seq());
    }
}

// Issue 25: commands the bridge refuses used to abort fins-bridge (bad_alloc, exit 134), and a
// retained DCMD at every start. Now: a retained DCMD waiting at start, then every refused kind
// of command, are logged and counted, none written, and the bridge goes on (a Rebirth after
// them is answered). Also: the first DBIRTH carries the first poll's values, bdSeq counts
// CONNECTs (an unreachable first broker costs none), the stats count Sparkplug publishes.
TEST(SparkplugMqtt, RefusedAndRetainedCommandsEndNothingAndTheFirstDbirthCarriesValues) {
    if (tb::mosquitto_path().empty()) GTEST_SKIP() << "mosquitto is not installed";
    fins::test::ScratchDir dir("sparkplug-refused");
    tb::Mosquitto broker(dir.path());
    ASSERT_TRUE(broker.started());
    fins::test::Finsd finsd({});
    ASSERT_TRUE(finsd.started());
    tb::CountingRelay relay(1, finsd.port());
    const auto dead = tb::free_tcp_port();  // nothing listens: the first broker fails
    const std::string conf =
        "[bridge]\ninstance = \"edge-1\"\npayload = \"sparkplug\"\nstats_s = 1\n"
        "[mqtt]\nhosts = [\"127.0.0.1:" +
        std::to_string(dead) + "\", \"127.0.0.1:" + std::to_string(broker.port()) +
        "\"]\ntopic_prefix = \"plant\"\nbackoff_min_ms = 50\nbackoff_max_ms = 200\n"
        "[[plc]]\nname = \"press1\"\nhost = \"127.0.0.1\"\nport = " +
        std::to_string(relay.port(0)) +
        "\n[[plc.group]]\nname = \"fast\"\ninterval_ms = 100\n"
        "tags = [ { name = \"speed\", address = \"D100\", type = \"int16\" },\n"
        "         { name = \"temp\", address = \"D200\", type = \"float\", writable = true } ]\n"
        "[[plc.group]]\nname = \"slow\"\ninterval_ms = 300\n"
        "tags = [ { name = \"count\", address = \"D300\", type = \"uint32\" } ]\n";
    const auto conf_path = dir.write("bridge.toml", conf);
    tb::Recorder rec(broker.port(), {"spBv1.0/#", "plant/$bridge/+/stats"});
    ASSERT_TRUE(rec.connected());

    // A valid DCMD, retained: the broker hands it to the bridge as it subscribes, every start.
    const auto metric = [](const std::function<void(pb::Payload::Metric&)>& set) {
        pb::Payload p;
        p.set_timestamp(1);
        set(*p.add_metrics());
        return p.SerializeAsString();
    };
    const auto temp = metric([](auto& m) {
        m.set_name("fast/temp");
        m.set_datatype(pb::Float);
        m.set_float_value(7.5F);
    });
    const std::string dcmd = "spBv1.0/plant/DCMD/edge-1/press1";
    const std::string ncmd = "spBv1.0/plant/NCMD/edge-1";
    rec.publish(dcmd, temp, 1, true);
    ASSERT_TRUE(rec.wait_for([&](const tb::Received& r) { return r.topic == dcmd; }, 10s));

    tb::Child bridge({tb::bridge_path, "--config", conf_path}, dir.path() / "bridge.log");
    ASSERT_TRUE(
        rec.wait([](const auto& ms) { return count_verb(decode_all(ms), "DBIRTH") >= 1; }, 30s))
        << bridge.log();
    auto ds = decode_all(rec.messages());
    // bdSeq 0: the attempt on the dead broker sent no CONNECT.
    ASSERT_EQ(ds[0].verb, "DCMD");
    ASSERT_EQ(ds[1].verb, "NBIRTH");
    EXPECT_EQ(bdseq_of(ds[1].payload), 0);
    // The DBIRTH waited for both groups' first values: none is null.
    ASSERT_EQ(ds[2].verb, "DBIRTH");
    ASSERT_EQ(ds[2].payload.metrics_size(), 3);
    for (const auto& m : ds[2].payload.metrics())
        EXPECT_FALSE(m.is_null()) << m.name();

    // Every refused kind of command; then a Rebirth, answered: the bridge lived through them.
    const std::vector<std::pair<std::string, std::string>> refused{
        {dcmd, metric([](auto& m) {  // read-only
             m.set_name("fast/speed");
             m.set_int_value(3);
         })},
        {dcmd, metric([](auto& m) {  // unknown metric
             m.set_name("fast/nope");
             m.set_int_value(3);
         })},
        {dcmd, metric([](auto& m) {  // the wrong value field for a Float
             m.set_name("fast/temp");
             m.set_int_value(3);
         })},
        {"spBv1.0/plant/DCMD/edge-1/nope", temp},  // unknown device
        {ncmd, metric([](auto& m) {
             m.set_name("Node Control/Rebirth");
             m.set_boolean_value(false);
         })},
        {ncmd, metric([](auto& m) {  // unknown node metric
             m.set_name("Node Control/Reboot");
             m.set_boolean_value(true);
         })},
        {ncmd, "\xff\xff\xff"},  // not protobuf
        {dcmd, "\xff\xff\xff"},
    };
    for (const auto& [topic, payload] : refused)
        rec.publish(topic, payload, 0);
    const auto before = rec.count();
    rec.publish(ncmd, metric([](auto& m) {
                    m.set_name("Node Control/Rebirth");
                    m.set_boolean_value(true);
                }),
                0);
    ASSERT_TRUE(rec.wait(
        [&](const auto& ms) {
            return count_verb(
                       decode_all({ms.begin() + static_cast<std::ptrdiff_t>(before), ms.end()}),
                       "NBIRTH") >= 1;
        },
        10s))
        << bridge.log();
    EXPECT_TRUE(bridge.running()) << bridge.log();

    // The stats: 1 retained + 8 refused, none failed; the Sparkplug messages counted as
    // published (at least those seen so far on spBv1.0/).
    std::size_t seen = 0;
    for (const auto& m : rec.messages())
        seen += m.topic.rfind("spBv1.0/plant/D", 0) == 0 || m.topic.rfind("spBv1.0/plant/N", 0) == 0
                    ? 1U
                    : 0U;
    seen -= 1 + refused.size() + 1;  // the commands are the recorder's, not the bridge's
    const auto stats = rec.wait_topic(
        "plant/$bridge/edge-1/stats",
        [&](const nlohmann::json& j) {
            return j.value("commands_rejected", 0U) >= 1 + refused.size() &&
                   j.value("published", std::size_t{0}) >= seen;
        },
        10s);
    ASSERT_TRUE(stats) << bridge.log();
    EXPECT_EQ(stats->json().value("commands_rejected", 0U), 1 + refused.size());
    EXPECT_EQ(stats->json().value("commands_failed", 1U), 0U);
    EXPECT_EQ(relay.writes(0), 0U);  // nothing was written
    EXPECT_TRUE(bridge.running());
    EXPECT_NE(bridge.log().find("retained DCMD"), std::string::npos);
}
