// The `fins` control verbs against a real finsd: run, stop, cpu-data, connections,
// cycle-time, clock. Output, --json and exit codes (0 ok, 2 usage, 4 end code).
#include <chrono>
#include <ctime>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "integration/support/finsd_process.hpp"

namespace fins::test {
namespace {

class CliControl : public FinsdTest {
  protected:
    nlohmann::json json(std::vector<std::string> args, int expected_exit = 0) {
        args.push_back("--json");
        auto r = fins(args);
        EXPECT_EQ(r.exit_code, expected_exit) << r.out << r.err;
        return nlohmann::json::parse(r.out, nullptr, false);
    }
};

TEST_F(CliControl, StopAndRunChangeTheMode) {
    auto stop = fins({"stop"});
    EXPECT_EQ(stop.exit_code, 0) << stop.err;
    EXPECT_EQ(stop.out, "PLC in PROGRAM mode\n");
    // 06 20 is refused in PROGRAM mode: end code 2203, exit 4.
    auto refused = json({"cycle-time"}, 4);
    EXPECT_EQ(refused["error"]["end_code"], "2203");
    auto run = fins({"run"}, true);
    EXPECT_EQ(run.exit_code, 0) << run.err;
    EXPECT_EQ(run.out, "PLC in RUN mode\n");
    EXPECT_EQ(json({"run", "--monitor"})["mode"], "monitor");
    EXPECT_EQ(json({"stop"})["mode"], "program");
}

TEST_F(CliControl, CpuDataSections) {
    auto all = json({"cpu-data"});
    EXPECT_TRUE(all["model"].is_string());
    EXPECT_FALSE(all["model"].get<std::string>().empty());
    EXPECT_EQ(all["area_data"]["iom_kbytes"], 23);
    EXPECT_TRUE(all.contains("racks"));
    auto area = json({"cpu-data", "--section", "area"});
    EXPECT_EQ(area["model"], all["model"]);
    EXPECT_FALSE(area.contains("racks"));
    auto units = json({"cpu-data", "--section", "units"});
    EXPECT_FALSE(units.contains("model"));
    EXPECT_EQ(units["racks"], all["racks"]);
    auto text = fins({"cpu-data"});
    EXPECT_EQ(text.exit_code, 0);
    EXPECT_EQ(text.out.rfind("model              " + all["model"].get<std::string>() + "\n", 0), 0u)
        << text.out;
    EXPECT_EQ(fins({"cpu-data", "--section", "nonsense"}).exit_code, 2);
}

TEST_F(CliControl, ConnectionsListsUnitsFromTheCpuUnit) {
    auto doc = json({"connections"});
    ASSERT_TRUE(doc["units"].is_array());
    ASSERT_FALSE(doc["units"].empty());
    EXPECT_EQ(doc["units"][0]["unit_address"], "00");
    EXPECT_EQ(doc["last_unit_included"], true);
    auto one = json({"connections", "00", "1"});
    EXPECT_EQ(one["units"].size(), 1u);
    // A missing unit: the answer starts at the next one.
    auto next = json({"connections", "0x01", "1"});
    if (!next["units"].empty()) {
        EXPECT_GT(next["units"][0]["unit_address"].get<std::string>(), "01");
    }
    auto text = fins({"connections", "00", "1"});
    EXPECT_EQ(text.out.rfind("00  ", 0), 0u) << text.out;
    EXPECT_EQ(fins({"connections", "XYZ"}).exit_code, 2);
    EXPECT_EQ(fins({"connections", "00", "26"}).exit_code, 2);
    EXPECT_EQ(fins({"connections", "00", "0"}).exit_code, 2);
}

TEST_F(CliControl, CycleTimeReadAndReset) {
    auto text = fins({"cycle-time"});
    ASSERT_EQ(text.exit_code, 0) << text.err;
    EXPECT_EQ(text.out.rfind("average ", 0), 0u) << text.out;
    EXPECT_NE(text.out.find(" ms\nmaximum "), std::string::npos) << text.out;
    auto doc = json({"cycle-time"});
    EXPECT_TRUE(doc["unit_0_1ms"]["average"].is_number_unsigned());
    EXPECT_GE(doc["unit_0_1ms"]["maximum"].get<unsigned>(),
              doc["unit_0_1ms"]["minimum"].get<unsigned>());
    auto reset = fins({"cycle-time", "--reset"});
    EXPECT_EQ(reset.exit_code, 0);
    EXPECT_EQ(reset.out, "cycle time maximum and minimum initialized\n");
}

TEST_F(CliControl, ClockSetReadAndErrors) {
    auto set = fins({"clock", "--set", "2030-01-02 03:04:05"});
    ASSERT_EQ(set.exit_code, 0) << set.err;
    EXPECT_EQ(set.out, "clock set to 2030-01-02 03:04:05 Wed\n");
    auto doc = json({"clock"});
    // The clock keeps running: a second or two may have passed.
    EXPECT_EQ(doc["time"].get<std::string>().substr(0, 17), "2030-01-02 03:04:");
    EXPECT_EQ(doc["day_of_week"], 3);
    EXPECT_EQ(doc["day"], "Wed");

    // --day-of-week is sent as given (5-3-20: not cross-checked).
    EXPECT_EQ(json({"clock", "--set", "2030-01-02 03:04", "--day-of-week", "6"})["day_of_week"], 6);
    EXPECT_EQ(json({"clock"})["day_of_week"], 6);
    // Without a day of week the PLC keeps its own.
    EXPECT_EQ(fins({"clock", "--set", "2031-05-05T10:00:00", "--keep-day-of-week"}).exit_code, 0);
    auto kept = json({"clock"});
    EXPECT_EQ(kept["time"].get<std::string>().substr(0, 14), "2031-05-05 10:");
    EXPECT_EQ(kept["day_of_week"], 6);

    // Range errors come from the PLC (110C, exit 4); malformed text is a usage error.
    auto bad = json({"clock", "--set", "2030-02-30 00:00:00"}, 4);
    EXPECT_EQ(bad["error"]["end_code"], "110C");
    EXPECT_EQ(fins({"clock", "--set", "2030-13-01 00:00"}).exit_code, 4);
    EXPECT_EQ(fins({"clock", "--set", "1997-01-01 00:00"}).exit_code, 2);
    EXPECT_EQ(fins({"clock", "--set", "tomorrow"}).exit_code, 2);
    EXPECT_EQ(fins({"clock", "--set", "2030-01-01 00:00", "--sync"}).exit_code, 2);
    EXPECT_EQ(fins({"clock", "--day-of-week", "3"}).exit_code, 2);
    EXPECT_EQ(fins({"clock", "--set", "2030-01-01 00:00", "--day-of-week", "7"}).exit_code, 2);
}

TEST_F(CliControl, ClockSyncTakesTheHostsLocalTime) {
    ASSERT_EQ(fins({"clock", "--set", "2040-01-01 00:00"}).exit_code, 0);
    auto sync = fins({"clock", "--sync"}, true);
    ASSERT_EQ(sync.exit_code, 0) << sync.err;
    auto doc = json({"clock"});
    std::tm tm{};
    const auto text = doc["time"].get<std::string>();
    ASSERT_NE(::strptime(text.c_str(), "%Y-%m-%d %H:%M:%S", &tm), nullptr) << text;
    tm.tm_isdst = -1;
    const auto plc_time = std::mktime(&tm);
    const auto host_time = std::time(nullptr);
    EXPECT_LE(std::abs(static_cast<long>(host_time - plc_time)), 10L) << text;
}

}  // namespace
}  // namespace fins::test
