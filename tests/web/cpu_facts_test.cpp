// The page's CPU Unit facts (web/cpu_facts.hpp): areas at the model's sizes, and a clock
// and cycle time that stay put while nothing happens, so an idle page gets no messages.
#include <gtest/gtest.h>

#include <chrono>

#include <nlohmann/json.hpp>

#include "fins/commands/clock.hpp"
#include "plc/plc.hpp"
#include "server/sessions/server.hpp"
#include "transport/asio.hpp"
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

// W342 5-3-18: the CPU Unit cycles from power-on whether anyone asks or not. Its server
// powers it up when it starts; a minute later, with not one request in between, 06 20 and
// the page's status show what a unit that ran that minute shows, and showing it changes
// nothing.
TEST(CpuFacts, W342_5_3_18_CycleTimesRunFromPowerOnWhetherAnyoneAsksOrNot) {
    using std::chrono::minutes;
    using std::chrono::seconds;
    asio::io_context io;
    plc::Plc plc;
    server::ServerOptions options;
    options.bind_address = "127.0.0.1";
    options.port = 0;
    const auto before = std::chrono::system_clock::now();
    auto server = server::Server::start(io, plc, options);
    ASSERT_TRUE(server) << server.error().message();
    const auto after = std::chrono::system_clock::now();
    EXPECT_TRUE(plc.scan_cycle().powered());

    const auto later = after + minutes(1);
    const auto& cycle = plc.scan_cycle();
    const auto base = plc::ScanCycle::base_cycle(plc.profile());
    const auto at = [&](auto t) {
        return plc::ScanCycle::cycle_at(base, plc::ScanCycle::to_ticks(t));
    };
    // Every cycle since power-on (between `before` and `after`) has run.
    EXPECT_GE(cycle.cycles(later) + 1, at(later) - at(after));
    EXPECT_LE(cycle.cycles(later), at(later) - at(before));
    // A minute holds every jitter value: the maximum and minimum have settled.
    const auto times = cycle.times(later);
    EXPECT_EQ(times.maximum, static_cast<std::uint32_t>(base + 3));
    EXPECT_EQ(times.minimum, static_cast<std::uint32_t>(base - 2));
    EXPECT_NE(times.average, 0U);

    Json status;
    web::add_cpu_facts(plc, status, later);
    EXPECT_EQ(status["cycle_time"]["max_ms"].get<double>(), times.maximum / 10.0);
    EXPECT_EQ(status["cycle_time"]["min_ms"].get<double>(), times.minimum / 10.0);
    // Statuses built at other times leave what 06 20 reads at `later` as it was.
    Json other;
    web::add_cpu_facts(plc, other, later + minutes(5));
    web::add_cpu_facts(plc, other, after + seconds(1));
    EXPECT_EQ(cycle.times(later), times);
    server->get()->stop();
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
