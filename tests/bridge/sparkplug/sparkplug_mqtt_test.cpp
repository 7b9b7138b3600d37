// fins-bridge in Sparkplug B mode against real mosquitto and finsd, with a subscriber that
// decodes every message with the generated protobuf code: the birth sequence, seq through
// 255 -> 0, rebirth on NCMD, a DCMD write executed once (counted on the wire), and the NDEATH
// Will with the NBIRTH's bdSeq after kill -9.
#include <gtest/gtest.h>

#include "bridge/cluster/processes.hpp"
#include "fins/values.hpp"
#include "integration/finsd_run.hpp"
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
        EXPECT_TRUE(d.payload.ParseFromString(m.payload)) << m.topic;
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
    tb::Recorder rec(broker.port(), {"spBv1.0/#"});
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
