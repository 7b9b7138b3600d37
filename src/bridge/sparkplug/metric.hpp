// Sparkplug B metric values: a tag's value as the bridge holds it, and its encoding into and
// out of a protobuf Metric (Sparkplug 3.0 chapter 6, "Datatype Details").
//
// The wire rules: Int8/16/32 and UInt8/16/32 travel in int_value (uint32; a signed value as
// its two's complement, so Int16 -2 is 0xFFFFFFFE), Int64/UInt64/DateTime in long_value
// (uint64), Float in float_value, Double in double_value, Boolean in boolean_value,
// String/Text/UUID in string_value. A value that could not be read is sent with is_null and
// the property Quality = 0 (BAD), never as a made-up number.
#pragma once

#include <cstdint>
#include <string>
#include <string_view>
#include <variant>

#include "sparkplug_b.pb.h"

namespace fins::bridge::sparkplug {

using DataType = finskit::sparkplug::pb::DataType;
using PbPayload = finskit::sparkplug::pb::Payload;
using PbMetric = finskit::sparkplug::pb::Payload::Metric;

// A value as the bridge holds it. monostate = no value (the read failed).
using MetricValue =
    std::variant<std::monostate, bool, std::int64_t, std::uint64_t, double, std::string>;

// The Quality property's codes (chapter 6, "Quality Codes").
inline constexpr std::int32_t quality_bad = 0;
inline constexpr std::int32_t quality_good = 192;
inline constexpr std::int32_t quality_stale = 500;

// The Sparkplug datatype for a bridge tag type name ("bool", "int16", "uint16", "int32",
// "uint32", "int64", "uint64", "float", "double", "bcd16", "bcd32", "string", ...): the same
// names as `fins --as`. Unknown names give DataType::Unknown.
DataType datatype_for(std::string_view tag_type) noexcept;
std::string_view datatype_name(DataType t) noexcept;

// Writes v into m as datatype t (v is converted: an int64 into Int16 keeps the low 16 bits'
// two's complement, as the PLC word holds it). monostate sets is_null and Quality BAD.
void encode_value(PbMetric& m, DataType t, const MetricValue& v);

// Reads the value of an incoming metric (a DCMD or NCMD) as datatype t: the oneof member the
// specification names for t must be set; an Int16 int_value is sign-extended from 16 bits and
// must fit. Returns monostate with a reason in *error when it does not.
MetricValue decode_value(const PbMetric& m, DataType t, std::string* error);

}  // namespace fins::bridge::sparkplug
