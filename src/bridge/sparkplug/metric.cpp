#include "bridge/sparkplug/metric.hpp"

#include <array>
#include <cmath>
#include <limits>
#include <utility>

namespace fins::bridge::sparkplug {
namespace pb = finskit::sparkplug::pb;

namespace {

struct TypeName {
    std::string_view tag_type;
    DataType datatype;
};

// Tag type names (the `fins --as` names the bridge's config uses) to Sparkplug datatypes.
// BCD words hold unsigned decimal numbers; "bits" and "bool" are one bit.
constexpr std::array type_names{
    TypeName{"bool", pb::Boolean},  TypeName{"bit", pb::Boolean},   TypeName{"int16", pb::Int16},
    TypeName{"uint16", pb::UInt16}, TypeName{"word", pb::UInt16},   TypeName{"hex", pb::UInt16},
    TypeName{"int32", pb::Int32},   TypeName{"uint32", pb::UInt32}, TypeName{"int64", pb::Int64},
    TypeName{"uint64", pb::UInt64}, TypeName{"float", pb::Float},   TypeName{"real", pb::Float},
    TypeName{"double", pb::Double}, TypeName{"lreal", pb::Double},  TypeName{"bcd", pb::UInt16},
    TypeName{"bcd16", pb::UInt16},  TypeName{"bcd32", pb::UInt32},  TypeName{"string", pb::String},
};

// The value as a 64-bit two's complement pattern, whatever alternative holds it.
std::uint64_t as_bits(const MetricValue& v) {
    if (const auto* b = std::get_if<bool>(&v)) return *b ? 1U : 0U;
    if (const auto* i = std::get_if<std::int64_t>(&v)) return static_cast<std::uint64_t>(*i);
    if (const auto* u = std::get_if<std::uint64_t>(&v)) return *u;
    if (const auto* d = std::get_if<double>(&v)) {
        // Saturated: converting a double that no 64-bit integer holds is undefined
        // behaviour (a Double metric's 1e300 came here too, for nothing).
        if (std::isnan(*d)) return 0;
        if (*d < 0) {
            if (*d < -0x1p63) return std::uint64_t{1} << 63;  // INT64_MIN's pattern
            return static_cast<std::uint64_t>(static_cast<std::int64_t>(*d));
        }
        if (*d >= 0x1p64) return std::numeric_limits<std::uint64_t>::max();
        return static_cast<std::uint64_t>(*d);
    }
    return 0;
}

double as_double(const MetricValue& v) {
    if (const auto* d = std::get_if<double>(&v)) return *d;
    if (const auto* i = std::get_if<std::int64_t>(&v)) return static_cast<double>(*i);
    if (const auto* u = std::get_if<std::uint64_t>(&v)) return static_cast<double>(*u);
    if (const auto* b = std::get_if<bool>(&v)) return *b ? 1.0 : 0.0;
    return 0.0;
}

void set_quality_bad(PbMetric& m) {
    auto* props = m.mutable_properties();
    props->add_keys("Quality");
    auto* q = props->add_values();
    q->set_type(pb::Int32);
    q->set_int_value(static_cast<std::uint32_t>(quality_bad));
}

}  // namespace

DataType datatype_for(std::string_view tag_type) noexcept {
    for (const auto& t : type_names)
        if (t.tag_type == tag_type) return t.datatype;
    return pb::Unknown;
}

std::string_view datatype_name(DataType t) noexcept {
    const auto& name = pb::DataType_Name(t);
    return name;
}

void encode_value(PbMetric& m, DataType t, const MetricValue& v) {
    if (std::holds_alternative<std::monostate>(v)) {
        m.set_is_null(true);
        set_quality_bad(m);
        return;
    }
    const std::uint64_t bits = as_bits(v);
    switch (t) {
        case pb::Int8:
            m.set_int_value(static_cast<std::uint32_t>(static_cast<std::int8_t>(bits)));
            break;
        case pb::Int16:
            m.set_int_value(static_cast<std::uint32_t>(static_cast<std::int16_t>(bits)));
            break;
        case pb::Int32:
            m.set_int_value(static_cast<std::uint32_t>(static_cast<std::int32_t>(bits)));
            break;
        case pb::UInt8:
            m.set_int_value(static_cast<std::uint32_t>(bits & 0xFFU));
            break;
        case pb::UInt16:
            m.set_int_value(static_cast<std::uint32_t>(bits & 0xFFFFU));
            break;
        case pb::UInt32:
            m.set_int_value(static_cast<std::uint32_t>(bits));
            break;
        case pb::Int64:
        case pb::UInt64:
        case pb::DateTime:
            m.set_long_value(bits);
            break;
        case pb::Float:
            m.set_float_value(static_cast<float>(as_double(v)));
            break;
        case pb::Double:
            m.set_double_value(as_double(v));
            break;
        case pb::Boolean:
            m.set_boolean_value(bits != 0);
            break;
        case pb::String:
        case pb::Text:
        case pb::UUID:
            if (const auto* s = std::get_if<std::string>(&v)) m.set_string_value(*s);
            break;
        default:
            m.set_is_null(true);
            break;
    }
}

MetricValue decode_value(const PbMetric& m, DataType t, std::string* error) {
    auto fail = [&](std::string why) -> MetricValue {
        if (error) *error = std::move(why);
        return std::monostate{};
    };
    if (m.is_null()) return fail("the metric is null");
    auto want = [&](PbMetric::ValueCase c, const char* field) -> bool {
        if (m.value_case() == c) return true;
        if (error)
            *error =
                std::string("a ") + std::string(datatype_name(t)) + " value must be in " + field;
        return false;
    };
    // A signed value of `bits` bits arrives as the two's complement in 32 bits: sign-extend
    // and accept only patterns that are a sign extension (else the number did not fit).
    auto signed_in = [&](unsigned bits) -> MetricValue {
        if (!want(PbMetric::kIntValue, "int_value")) return std::monostate{};
        const auto raw = static_cast<std::int32_t>(m.int_value());
        const std::int64_t lo = -(std::int64_t{1} << (bits - 1));
        const std::int64_t hi = (std::int64_t{1} << (bits - 1)) - 1;
        if (raw < lo || raw > hi)
            return fail("the value does not fit " + std::string(datatype_name(t)));
        return std::int64_t{raw};
    };
    auto unsigned_in = [&](unsigned bits) -> MetricValue {
        if (!want(PbMetric::kIntValue, "int_value")) return std::monostate{};
        const std::uint64_t raw = m.int_value();
        if (bits < 32 && raw > ((std::uint64_t{1} << bits) - 1))
            return fail("the value does not fit " + std::string(datatype_name(t)));
        return raw;
    };
    switch (t) {
        case pb::Int8:
            return signed_in(8);
        case pb::Int16:
            return signed_in(16);
        case pb::Int32:
            return signed_in(32);
        case pb::UInt8:
            return unsigned_in(8);
        case pb::UInt16:
            return unsigned_in(16);
        case pb::UInt32:
            return unsigned_in(32);
        case pb::Int64:
            if (!want(PbMetric::kLongValue, "long_value")) return std::monostate{};
            return static_cast<std::int64_t>(m.long_value());
        case pb::UInt64:
        case pb::DateTime:
            if (!want(PbMetric::kLongValue, "long_value")) return std::monostate{};
            return m.long_value();
        case pb::Float:
            if (!want(PbMetric::kFloatValue, "float_value")) return std::monostate{};
            return static_cast<double>(m.float_value());
        case pb::Double:
            if (!want(PbMetric::kDoubleValue, "double_value")) return std::monostate{};
            return m.double_value();
        case pb::Boolean:
            if (!want(PbMetric::kBooleanValue, "boolean_value")) return std::monostate{};
            return m.boolean_value();
        case pb::String:
        case pb::Text:
        case pb::UUID:
            if (!want(PbMetric::kStringValue, "string_value")) return std::monostate{};
            return m.string_value();
        default:
            return fail("datatype " + std::string(datatype_name(t)) + " cannot be written");
    }
}

}  // namespace fins::bridge::sparkplug
