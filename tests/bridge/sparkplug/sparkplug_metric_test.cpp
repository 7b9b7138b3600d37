// Metric values through protobuf and back: each datatype lands in the oneof member the
// specification names for it, signed values as two's complement, and bad input is refused.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "bridge/sparkplug/metric.hpp"

namespace sp = fins::bridge::sparkplug;
namespace pb = finskit::sparkplug::pb;

namespace {

// Encode, serialise, parse, decode.
sp::MetricValue round_trip(pb::DataType t, const sp::MetricValue& v,
                           pb::Payload::Metric* wire = nullptr) {
    pb::Payload p;
    sp::encode_value(*p.add_metrics(), t, v);
    pb::Payload back;
    EXPECT_TRUE(back.ParseFromString(p.SerializeAsString()));
    if (wire) *wire = back.metrics(0);
    std::string why;
    auto out = sp::decode_value(back.metrics(0), t, &why);
    EXPECT_TRUE(why.empty()) << why;
    return out;
}

}  // namespace

TEST(SparkplugMetric, TagTypesMapToSparkplugDatatypes) {
    EXPECT_EQ(sp::datatype_for("int16"), pb::Int16);
    EXPECT_EQ(sp::datatype_for("uint16"), pb::UInt16);
    EXPECT_EQ(sp::datatype_for("int32"), pb::Int32);
    EXPECT_EQ(sp::datatype_for("uint32"), pb::UInt32);
    EXPECT_EQ(sp::datatype_for("float"), pb::Float);
    EXPECT_EQ(sp::datatype_for("double"), pb::Double);
    EXPECT_EQ(sp::datatype_for("bool"), pb::Boolean);
    EXPECT_EQ(sp::datatype_for("bcd"), pb::UInt16);
    EXPECT_EQ(sp::datatype_for("string"), pb::String);
    EXPECT_EQ(sp::datatype_for("nonsense"), pb::Unknown);
    EXPECT_EQ(sp::datatype_name(pb::Int16), "Int16");
}

TEST(SparkplugMetric, SignedValuesTravelAsTwosComplementInUint32) {
    pb::Payload::Metric wire;
    EXPECT_EQ(std::get<std::int64_t>(round_trip(pb::Int16, std::int64_t{-2}, &wire)), -2);
    EXPECT_EQ(wire.int_value(), 0xFFFFFFFEU);
    EXPECT_EQ(std::get<std::int64_t>(round_trip(pb::Int8, std::int64_t{-128}, &wire)), -128);
    EXPECT_EQ(std::get<std::int64_t>(
                  round_trip(pb::Int32, std::int64_t{std::numeric_limits<std::int32_t>::min()})),
              std::numeric_limits<std::int32_t>::min());
    EXPECT_EQ(std::get<std::int64_t>(round_trip(pb::Int64, std::int64_t{-5}, &wire)), -5);
    EXPECT_EQ(wire.value_case(), pb::Payload::Metric::kLongValue);
}

TEST(SparkplugMetric, EveryBasicTypeRoundTrips) {
    EXPECT_EQ(std::get<std::uint64_t>(round_trip(pb::UInt16, std::uint64_t{65535})), 65535U);
    EXPECT_EQ(std::get<std::uint64_t>(round_trip(pb::UInt32, std::uint64_t{4000000000U})),
              4000000000U);
    EXPECT_EQ(std::get<std::uint64_t>(round_trip(pb::UInt64, std::uint64_t{1} << 60)),
              std::uint64_t{1} << 60);
    EXPECT_EQ(std::get<double>(round_trip(pb::Float, 1.5)), 1.5);
    EXPECT_EQ(std::get<double>(round_trip(pb::Double, 1e300)), 1e300);
    EXPECT_EQ(std::get<bool>(round_trip(pb::Boolean, true)), true);
    EXPECT_EQ(std::get<std::string>(round_trip(pb::String, std::string("ABC"))), "ABC");
    // A uint16 word read as an int (the bridge's integer holder) still encodes as its pattern.
    EXPECT_EQ(std::get<std::uint64_t>(round_trip(pb::UInt16, std::int64_t{1234})), 1234U);
}

// A double that no 64-bit integer holds saturates (converting it would be undefined
// behaviour, which clang's UBSan reports): the largest pattern, INT64_MIN's, 0 for NaN.
TEST(SparkplugMetric, ADoubleBeyondSixtyFourBitsSaturates) {
    EXPECT_EQ(std::get<std::uint64_t>(round_trip(pb::UInt64, 1e300)),
              std::numeric_limits<std::uint64_t>::max());
    EXPECT_EQ(std::get<std::int64_t>(round_trip(pb::Int64, -1e300)),
              std::numeric_limits<std::int64_t>::min());
    EXPECT_EQ(std::get<std::uint64_t>(round_trip(pb::UInt64, std::nan(""))), 0U);
    EXPECT_EQ(std::get<std::int64_t>(round_trip(pb::Int64, -2.5)), -2);
}

TEST(SparkplugMetric, AFailedReadIsNullWithQualityBad) {
    pb::Payload::Metric m;
    sp::encode_value(m, pb::Int16, std::monostate{});
    EXPECT_TRUE(m.is_null());
    EXPECT_EQ(m.value_case(), pb::Payload::Metric::VALUE_NOT_SET);
    ASSERT_EQ(m.properties().keys_size(), 1);
    EXPECT_EQ(m.properties().keys(0), "Quality");
    EXPECT_EQ(m.properties().values(0).type(), static_cast<unsigned>(pb::Int32));
    EXPECT_EQ(m.properties().values(0).int_value(), static_cast<unsigned>(sp::quality_bad));
}

TEST(SparkplugMetric, DecodeRefusesWrongMemberOutOfRangeAndNull) {
    std::string why;
    pb::Payload::Metric m;
    m.set_int_value(70000);
    EXPECT_TRUE(std::holds_alternative<std::monostate>(sp::decode_value(m, pb::UInt16, &why)));
    EXPECT_NE(why.find("does not fit"), std::string::npos);
    m.set_int_value(0x00018000U);  // not a sign extension of a 16-bit value
    EXPECT_TRUE(std::holds_alternative<std::monostate>(sp::decode_value(m, pb::Int16, &why)));
    m.set_double_value(1.0);
    EXPECT_TRUE(std::holds_alternative<std::monostate>(sp::decode_value(m, pb::Float, &why)));
    EXPECT_NE(why.find("float_value"), std::string::npos);
    pb::Payload::Metric n;
    n.set_is_null(true);
    EXPECT_TRUE(std::holds_alternative<std::monostate>(sp::decode_value(n, pb::Boolean, &why)));
    pb::Payload::Metric t;
    t.set_bytes_value("x");
    EXPECT_TRUE(std::holds_alternative<std::monostate>(sp::decode_value(t, pb::Bytes, &why)));
}
