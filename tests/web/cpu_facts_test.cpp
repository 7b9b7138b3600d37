// The page's CPU Unit facts (web/cpu_facts.hpp): areas at the model's sizes, and a clock
// and cycle time that stay put while nothing happens, so an idle page gets no messages.
#include <gtest/gtest.h>

#include <chrono>

#include <nlohmann/json.hpp>

#include "fins/commands/clock.hpp"
#include "plc/plc.hpp"
#include "web/cpu_facts.hpp"

namespace fins::test {
namespace {

using Json = nlohmann::json;

std::uint32_t words_of(const Json& areas, const std::string& prefix) {
    for (const auto& a : areas)
        if (a["prefix"] == prefix) return a["words"].get<std::uint32_t>();
    return 0;
}

TEST(CpuFacts, AreasFollowTheModelsProfile) {
    for (const char* name : {"cj2h", "cs1h", "cj1m", "cp1h"}) {
        const auto* profile = plc::find_profile(name);
        ASSERT_NE(profile, nullptr) << name;
        const Json areas = web::memory_areas(*profile);
        EXPECT_EQ(words_of(areas, "CIO"), profile->cio_words) << name;
        EXPECT_EQ(words_of(areas, "H"), profile->holding_words) << name;
        EXPECT_EQ(words_of(areas, "A"), profile->auxiliary_words) << name;
        EXPECT_EQ(words_of(areas, "D"), profile->dm_words) << name;
        std::size_t banks = 0;
        for (const auto& a : areas)
            if (a["prefix"].get<std::string>().starts_with("E")) ++banks;
        EXPECT_EQ(banks, profile->em_banks) << name;
    }
    const Json cj2h = web::memory_areas(*plc::find_profile("cj2h"));
    EXPECT_EQ(cj2h.front()["prefix"], "CIO");
    EXPECT_EQ(words_of(cj2h, "E18_"), 32768U);  // bank 0x18, as parse_address writes it
}

TEST(CpuFacts, ClockIsAnOffsetThatMovesOnlyWhenTheClockIsSet) {
    plc::Plc plc;
    const auto now = std::chrono::system_clock::now();
    Json first;
    web::add_cpu_facts(plc, first, now);
    Json later;
    web::add_cpu_facts(plc, later, now + std::chrono::seconds(90));
    EXPECT_EQ(first["clock_offset_s"], later["clock_offset_s"]);
    const auto utc = std::chrono::duration_cast<std::chrono::seconds>(now.time_since_epoch());
    EXPECT_EQ(first["clock_offset_s"].get<std::int64_t>(), plc.clock().civil(now) - utc.count());
    // 07 02 sets the clock to 2030-01-01 00:00:00: the page then shows that, ticking.
    ClockWrite set{};
    set.year = 30;
    set.month = 1;
    set.day = 1;
    ASSERT_EQ(plc.clock().write(set, now), EndCode::normal_completion);
    Json after;
    web::add_cpu_facts(plc, after, now);
    EXPECT_EQ(after["clock_offset_s"].get<std::int64_t>(),
              plc::Clock::to_civil(2030, 1, 1, 0, 0, 0) - utc.count());
}

TEST(CpuFacts, CycleTimeSettlesOnAnIdlePlc) {
    plc::Plc plc;
    const auto start = std::chrono::system_clock::now();
    plc.change_mode(plc::OperatingMode::run, start);
    Json a;
    web::add_cpu_facts(plc, a, start + std::chrono::seconds(1));
    Json b;
    web::add_cpu_facts(plc, b, start + std::chrono::seconds(2));
    EXPECT_GT(a["cycle_time"]["base_ms"].get<double>(), 0.0);
    EXPECT_GT(a["cycle_time"]["max_ms"].get<double>(), 0.0);
    EXPECT_LE(a["cycle_time"]["min_ms"].get<double>(), a["cycle_time"]["max_ms"].get<double>());
    EXPECT_EQ(a["cycle_time"], b["cycle_time"]);
}

}  // namespace
}  // namespace fins::test
