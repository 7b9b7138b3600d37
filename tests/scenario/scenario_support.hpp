// What the scenario tests share: a host time to stamp, a tag definition, a compile that
// must succeed.
#pragma once

#include <gtest/gtest.h>

#include <chrono>
#include <memory>
#include <string>

#include "plc/plc.hpp"
#include "scenario/scenario.hpp"

namespace fins::scenario::test {

inline const plc::TimePoint now{std::chrono::seconds(1'700'000'000)};

inline TagDef tag(std::string address, SignalKind kind, ValueType type = ValueType::int16) {
    TagDef t;
    t.address.text = std::move(address);
    t.kind = kind;
    t.type = type;
    return t;
}

inline std::unique_ptr<Scenario> compile(ScenarioDef def, plc::Plc& plc) {
    auto s = Scenario::compile(std::move(def), plc);
    EXPECT_TRUE(s.has_value()) << (s ? "" : s.error().message);
    return s ? std::move(*s) : nullptr;
}

}  // namespace fins::scenario::test
