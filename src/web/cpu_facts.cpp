// The page's CPU Unit facts (contract in cpu_facts.hpp).
#include "web/cpu_facts.hpp"

#include <cstdint>
#include <string>

#include <fmt/core.h>

#include "plc/plc.hpp"

namespace fins::web {

namespace {

using Json = nlohmann::json;

// 06 20 counts in units of 0.1 ms (W342 5-3-18).
double tenths_to_ms(std::int64_t tenths) {
    return static_cast<double>(tenths) / 10.0;
}

}  // namespace

Json memory_areas(const plc::Profile& profile) {
    Json areas = Json::array();
    const auto add = [&](std::string prefix, std::uint32_t words) {
        if (words != 0) areas.push_back({{"prefix", std::move(prefix)}, {"words", words}});
    };
    add("CIO", profile.cio_words);
    add("W", profile.work_words);
    add("H", profile.holding_words);
    add("A", profile.auxiliary_words);
    add("T", profile.timers);
    add("C", profile.counters);
    add("D", profile.dm_words);
    for (unsigned bank = 0; bank < profile.em_banks; ++bank)
        add(fmt::format("E{:X}_", bank), profile.em_bank_words);
    return areas;
}

void add_cpu_facts(plc::Plc& plc, Json& status, std::chrono::system_clock::time_point now) {
    const auto utc = std::chrono::duration_cast<std::chrono::seconds>(now.time_since_epoch());
    status["clock_offset_s"] = plc.clock().civil(now) - utc.count();
    const auto times = plc.scan_cycle().times(now);
    status["cycle_time"] = {{"base_ms", tenths_to_ms(plc::ScanCycle::base_cycle(plc.profile()))},
                            {"max_ms", tenths_to_ms(times.maximum)},
                            {"min_ms", tenths_to_ms(times.minimum)}};
}

}  // namespace fins::web
