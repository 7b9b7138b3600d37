// A running scenario in a finsd process (issue 19): virtual time moved by `finsd ctl
// scenario advance`, client writes the scenario reacts to, events triggered by name,
// unit faults on the wire, reload, and the examples in examples/scenarios behaving like
// the process they describe.
#include <gtest/gtest.h>

#include <cmath>
#include <thread>

#include <nlohmann/json.hpp>

#include "fins/values.hpp"
#include "integration/support/finsd_process.hpp"

namespace fins::test {
namespace {

using Json = nlohmann::json;

const std::string& examples = scenario_examples;

Json scenario_status(const std::string& socket) {
    const auto r = ctl(socket, {"scenario", "status"});
    EXPECT_EQ(r.exit_code, 0) << r.err;
    return Json::parse(r.out, nullptr, false)["scenario"];
}

void run_for(const std::string& socket, double seconds) {
    const auto r = ctl(socket, {"scenario", "advance", std::to_string(seconds)});
    ASSERT_EQ(r.exit_code, 0) << r.err << r.out;
}

float read_float(Client& c, const std::string& address) {
    const auto w = words_of(c, address, 2);
    return w.size() == 2 ? words_to_float(w).value_or(-1.0f) : -1.0f;
}

std::int16_t read_int16(Client& c, const std::string& address) {
    const auto w = words_of(c, address, 1);
    return w.empty() ? std::int16_t{-1} : static_cast<std::int16_t>(w[0]);
}

void write_bit(Client& c, const std::string& address, bool on) {
    auto r = c.write_bits(addr(address), std::vector<bool>{on});
    ASSERT_TRUE(r.has_value()) << address;
}

TEST(ScenarioRun, TankFillsWhileThePumpRunsAndDrainsThroughTheValve) {
    ScratchDir dir("scenario-tank");
    const std::string socket = (dir.path() / "ctl.sock").string();
    Finsd d({"--scenario", examples + "tank.toml", "--control", socket});
    ASSERT_TRUE(d.started()) << d.result().err;
    auto c = d.client();
    ASSERT_NE(c, nullptr);
    run_for(socket, 10);
    EXPECT_EQ(read_float(*c, "D12"), 0.0f);  // nothing runs until the HMI says so
    write_bit(*c, "CIO0.00", true);          // pump on
    run_for(socket, 60);
    const float after_fill = read_float(*c, "D12");
    EXPECT_GT(after_fill, 100.0f);
    EXPECT_NEAR(read_float(*c, "D10"), 120.0f, 0.01);
    EXPECT_EQ(read_int16(*c, "D14"), static_cast<std::int16_t>(std::lround(after_fill / 10)));
    write_bit(*c, "CIO0.00", false);  // pump off, valve open
    write_bit(*c, "CIO0.01", true);
    run_for(socket, 30);
    EXPECT_LT(read_float(*c, "D12"), after_fill - 20.0f);
    EXPECT_EQ(read_int16(*c, "D16"), 60);

    const Json st = scenario_status(socket);
    EXPECT_EQ(st["time"], "virtual");
    EXPECT_EQ(st["ticks"], 1000);
    EXPECT_NEAR(st["time_s"].get<double>(), 100.0, 1e-6);
    // The scenario's writes show in the FINS write access log (node 0.0.0: the CPU Unit).
    const auto ctl_status = ctl(socket, {"status"});
    EXPECT_GE(Json::parse(ctl_status.out)["status"]["write_access_log_records"].get<int>(), 1);

    // Triggered by name: the level reading freezes while the tank keeps draining.
    ASSERT_EQ(ctl(socket, {"scenario", "trigger", "level_stuck"}).exit_code, 0);
    const auto frozen = read_int16(*c, "D14");
    run_for(socket, 10);
    EXPECT_EQ(read_int16(*c, "D14"), frozen);
    EXPECT_NE(ctl(socket, {"scenario", "trigger", "no_such_event"}).exit_code, 0);

    // `finsd ctl advance S` is `finsd ctl scenario advance S`.
    const auto alias = ctl(socket, {"advance", "2.5"});
    ASSERT_EQ(alias.exit_code, 0) << alias.err;
    const Json advanced = Json::parse(alias.out, nullptr, false);
    EXPECT_EQ(advanced["ok"], true) << alias.out;
    EXPECT_EQ(advanced["ticks"], 25) << alias.out;
    EXPECT_NEAR(advanced["time_s"].get<double>(), 112.5, 1e-6) << alias.out;
    EXPECT_NE(ctl(socket, {"advance"}).exit_code, 0);  // SECONDS is required
}

TEST(ScenarioRun, ConveyorCountsBoxesAndJamsOnSchedule) {
    ScratchDir dir("scenario-conveyor");
    const std::string socket = (dir.path() / "ctl.sock").string();
    Finsd d({"--scenario", examples + "conveyor.toml", "--control", socket});
    ASSERT_TRUE(d.started()) << d.result().err;
    auto c = d.client();
    ASSERT_NE(c, nullptr);
    write_bit(*c, "CIO1.00", true);  // start the belt
    run_for(socket, 20);
    EXPECT_EQ(read_int16(*c, "D20"), 30);
    // A box every 2 s: at 0.1 (the belt started after the t = 0 refresh), 2, 4 ... and
    // the one arriving at t = 20, which memory at t = 20 shows.
    EXPECT_EQ(read_int16(*c, "D21"), 11);
    run_for(socket, 285);  // t = 305: jammed since 300
    EXPECT_EQ(read_int16(*c, "D20"), 0);
    const auto during = read_int16(*c, "D21");
    const Json jammed = Json::parse(ctl(socket, {"status"}).out)["status"];
    EXPECT_EQ(jammed["error_code"], "410A") << jammed.dump();  // FAL 10
    run_for(socket, 10);
    EXPECT_EQ(read_int16(*c, "D21"), during);  // nothing passes the eye while jammed
    run_for(socket, 10);                       // t = 325: running again
    EXPECT_EQ(read_int16(*c, "D20"), 30);
    EXPECT_EQ(Json::parse(ctl(socket, {"status"}).out)["status"]["error_code"], "0000");
}

TEST(ScenarioRun, TemperaturePvFollowsTheSetpointWrittenOverFins) {
    ScratchDir dir("scenario-temperature");
    const std::string socket = (dir.path() / "ctl.sock").string();
    Finsd d({"--scenario", examples + "temperature.toml", "--control", socket});
    ASSERT_TRUE(d.started()) << d.result().err;
    auto c = d.client();
    ASSERT_NE(c, nullptr);
    run_for(socket, 1);
    EXPECT_NEAR(read_int16(*c, "D201"), 200, 15);
    ASSERT_TRUE(c->write_words(addr("D200"), std::vector<std::uint16_t>{800}).has_value());
    run_for(socket, 5);
    EXPECT_EQ(c->read_bits(addr("W20.00"), 1).value_or(std::vector<bool>{false})[0], true);
    EXPECT_GT(read_int16(*c, "D202"), 0);  // the heater is on
    run_for(socket, 200);                  // ten time constants
    EXPECT_NEAR(read_int16(*c, "D201"), 800, 15);
    EXPECT_EQ(c->read_bits(addr("W20.00"), 1).value_or(std::vector<bool>{true})[0], false);
}

// On the Loop Control Board profile, 02 40 on Basic PID block 001 answers the PV, SP and
// MV the scenario produces (examples/scenarios/temperature-lcb.toml), read over FINS with
// `fins loop-read` from the board (unit E1).
TEST(ScenarioRun, LoopControlBoardAnswersThePvTheScenarioProduces) {
    ScratchDir dir("scenario-temperature-lcb");
    const std::string socket = (dir.path() / "ctl.sock").string();
    Finsd d({"--config", examples + "temperature-lcb.toml", "--control", socket});
    ASSERT_TRUE(d.started()) << d.result().err;
    auto items = [&] {
        const auto r =
            run({std::string(FINS_BIN_DIR) + "/fins", "--port", std::to_string(d.port()),
                 "--timeout", "3", "--json", "--dest", "0.1.E1", "loop-read", "1", "6", "7", "8"});
        EXPECT_EQ(r.exit_code, 0) << r.err;
        std::vector<double> values;
        const Json j = Json::parse(r.out, nullptr, false);
        if (j.is_discarded()) return values;
        for (const auto& item : j["items"])
            values.push_back(item["value"].get<double>());
        return values;
    };
    run_for(socket, 1);
    auto pv_sp_mv = items();
    ASSERT_EQ(pv_sp_mv.size(), 3u);
    EXPECT_NEAR(pv_sp_mv[0], 1000, 75);  // PV 20.0 degC: 10.00 % of 0-200 degC
    auto c = d.client();
    ASSERT_NE(c, nullptr);
    ASSERT_TRUE(c->write_words(addr("D200"), std::vector<std::uint16_t>{800}).has_value());
    run_for(socket, 200);  // ten time constants
    pv_sp_mv = items();
    ASSERT_EQ(pv_sp_mv.size(), 3u);
    EXPECT_NEAR(pv_sp_mv[0], 5.0 * read_int16(*c, "D201"), 0.5);  // the PV of DM, in 0.01 %
    EXPECT_NEAR(pv_sp_mv[0], 4000, 75);                           // 80.0 degC = 40.00 %
    EXPECT_EQ(pv_sp_mv[1], 4000);                                 // SP 80.0 degC
    EXPECT_EQ(pv_sp_mv[2], 100 * read_int16(*c, "D202"));
}

TEST(ScenarioRun, APlantOfFiftyMachinesWithStaggeredFaults) {
    ScratchDir dir("scenario-plant");
    const std::string socket = (dir.path() / "ctl.sock").string();
    Finsd d({"--config", examples + "plant-50.toml", "--control", socket});
    ASSERT_TRUE(d.started()) << d.result().err;
    // Each CPU Unit has its own scenario time: only machine-03 moves to 35 s.
    ASSERT_EQ(ctl(socket, {"--plc", "machine-03", "scenario", "advance", "35"}).exit_code, 0);
    const auto status = [&](const char* plc) {
        return Json::parse(ctl(socket, {"--plc", plc, "status"}).out)["status"];
    };
    EXPECT_EQ(status("machine-03")["error_code"], "4103");  // FAL 3 from 30 s to 60 s
    EXPECT_EQ(status("machine-04")["error_code"], "0000");
    ASSERT_EQ(ctl(socket, {"--plc", "machine-04", "scenario", "advance", "45"}).exit_code, 0);
    EXPECT_EQ(status("machine-04")["error_code"], "4104");
    const Json s = Json::parse(ctl(socket, {"--plc", "machine-50", "scenario", "status"}).out);
    EXPECT_EQ(s["scenario"]["seed"], 50);
    EXPECT_EQ(s["scenario"]["events"].size(), 3u);  // FAL, stuck spindle, offline
}

TEST(ScenarioRun, SameSeedAndSameWritesAtTheSameTimesGiveTheSameMemory) {
    const auto run_once = [](const std::string& tag) {
        ScratchDir dir(tag);
        const std::string socket = (dir.path() / "ctl.sock").string();
        const auto file = dir.write("noisy.toml",
                                    "[scenario]\nseed = 42\ntime = \"virtual\"\n"
                                    "[[scenario.signal]]\naddress = \"D0\"\ntype = \"float\"\n"
                                    "kind = \"random_walk\"\nmin = -50\nmax = 50\nstep = 2\n"
                                    "[[scenario.link]]\naddress = \"D2\"\nexpr = \"D0 * 10 + "
                                    "noise(30) + D100\"\n[[scenario.signal]]\naddress = \"D3\"\n"
                                    "kind = \"lag\"\nsetpoint = \"D100\"\ntau_s = 5\nnoise = 4\n");
        Finsd d({"--scenario", file, "--control", socket});
        EXPECT_TRUE(d.started()) << d.result().err;
        auto c = d.client();
        std::vector<std::uint16_t> memory;
        if (!d.started() || c == nullptr) return memory;
        run_for(socket, 3.3);
        EXPECT_TRUE(c->write_words(addr("D100"), std::vector<std::uint16_t>{250}).has_value());
        run_for(socket, 7.1);
        return words_of(*c, "D0", 110);
    };
    const auto first = run_once("scenario-det-a");
    ASSERT_EQ(first.size(), 110u);
    EXPECT_EQ(first, run_once("scenario-det-b"));
}

TEST(ScenarioRun, UnitFaultsReachTheWire) {
    ScratchDir dir("scenario-faults");
    const std::string socket = (dir.path() / "ctl.sock").string();
    const auto file = dir.write("faults.toml",
                                "[scenario]\ntime = \"virtual\"\n"
                                "[[scenario.event]]\nname = \"off\"\nat_s = 1000\nduration_s = "
                                "5\nfault = \"offline\"\n"
                                "[[scenario.event]]\nname = \"dm\"\nat_s = 1000\nduration_s = "
                                "5\nfault = \"end_code\"\naddress = \"D0\"\nend_code = 0x1103\n");
    Finsd d({"--scenario", file, "--control", socket});
    ASSERT_TRUE(d.started()) << d.result().err;
    ClientOptions o;
    o.port = d.port();
    o.timeout = std::chrono::milliseconds(300);
    o.retries = 0;
    auto c = Client::connect(o);
    ASSERT_TRUE(c.has_value());
    ASSERT_EQ(ctl(socket, {"scenario", "trigger", "dm"}).exit_code, 0);
    auto r = (*c)->read_words(addr("D0"), 1);
    ASSERT_FALSE(r.has_value());
    EXPECT_EQ(r.error(), make_error_code(EndCode::address_range_error));
    EXPECT_TRUE((*c)->read_words(addr("H0"), 1).has_value());  // other areas answer
    ASSERT_EQ(ctl(socket, {"scenario", "trigger", "off"}).exit_code, 0);
    EXPECT_FALSE((*c)->read_words(addr("H0"), 1).has_value());  // no answer: timeout
    run_for(socket, 5.0);
    EXPECT_TRUE((*c)->read_words(addr("D0"), 1).has_value());  // both ended at 5 s
}

TEST(ScenarioRun, ReloadSwapsAGoodFileAndKeepsTheRunningOneOnABadFile) {
    ScratchDir dir("scenario-reload");
    const std::string socket = (dir.path() / "ctl.sock").string();
    const auto file = dir.write("s.toml",
                                "[scenario]\ntime = \"virtual\"\n[[scenario.signal]]\naddress = "
                                "\"D5\"\nkind = \"constant\"\nvalue = 11\n");
    Finsd d({"--scenario", file, "--control", socket});
    ASSERT_TRUE(d.started()) << d.result().err;
    auto c = d.client();
    run_for(socket, 1);
    EXPECT_EQ(read_int16(*c, "D5"), 11);
    dir.write("s.toml",
              "[scenario]\ntime = \"virtual\"\n[[scenario.signal]]\naddress = "
              "\"A5\"\nkind = \"constant\"\nvalue = 22\n");
    const auto bad = ctl(socket, {"scenario", "reload"});
    EXPECT_EQ(bad.exit_code, 2);
    EXPECT_NE(bad.err.find("s.toml:4:11: A5 is in a read-only area"), std::string::npos) << bad.err;
    dir.write("s.toml",
              "[scenario]\ntime = \"virtual\"\n[[scenario.signal]]\naddress = "
              "\"D5\"\nkind = \"constant\"\nvalue = 33\n");
    EXPECT_EQ(ctl(socket, {"scenario", "reload"}).exit_code, 0);
    run_for(socket, 1);
    EXPECT_EQ(read_int16(*c, "D5"), 33);
    EXPECT_EQ(scenario_status(socket)["reloads"], 1);
}

TEST(ScenarioRun, RealTimeTicksWithoutAdvance) {
    ScratchDir dir("scenario-real");
    const std::string socket = (dir.path() / "ctl.sock").string();
    const auto file = dir.write("s.toml",
                                "[scenario]\ntick_ms = 10\n[[scenario.signal]]\naddress = "
                                "\"D7\"\nkind = \"ramp\"\nmin = 0\nmax = 30000\nperiod_s = 300\n");
    Finsd d({"--scenario", file, "--control", socket});
    ASSERT_TRUE(d.started()) << d.result().err;
    auto c = d.client();
    // Bounded wait for the ramp to move (no timing assertion: only that time runs).
    std::int16_t v = 0;
    for (int i = 0; i < 200 && v <= 0; ++i) {
        std::this_thread::sleep_for(std::chrono::milliseconds(25));
        v = read_int16(*c, "D7");
    }
    EXPECT_GT(v, 0);
    EXPECT_EQ(ctl(socket, {"scenario", "pause"}).exit_code, 0);
    EXPECT_TRUE(scenario_status(socket)["paused"].get<bool>());
}

// compute = "thread" (finsd's scenario thread) and "io" (the I/O thread) run the same
// scenario: time runs, and a client's write to a counter is where it goes on from,
// whichever phase of a tick the write lands in (docs/scenarios.md "How writes reach
// memory").
TEST(ScenarioRun, ComputeOnTheScenarioThreadOrTheIoThreadAdoptsClientWrites) {
    for (const char* where : {"thread", "io"}) {
        SCOPED_TRACE(where);
        ScratchDir dir(std::string("scenario-compute-") + where);
        const auto file =
            dir.write("s.toml", std::string("[scenario]\ntick_ms = 10\ncompute = \"") + where +
                                    "\"\n[[scenario.signal]]\naddress = \"D8\"\nkind = "
                                    "\"counter\"\ninput = \"1\"\nrate = 100\n");
        Finsd d({"--scenario", file});
        ASSERT_TRUE(d.started()) << d.result().err;
        auto c = d.client();
        std::int16_t v = 0;
        for (int i = 0; i < 200 && v < 5; ++i) {
            std::this_thread::sleep_for(std::chrono::milliseconds(25));
            v = read_int16(*c, "D8");
        }
        ASSERT_GE(v, 5);
        ASSERT_TRUE(c->write_words(addr("D8"), std::vector<std::uint16_t>{20000}).has_value());
        for (int i = 0; i < 200 && (v < 20000 || v > 20000 + 5000); ++i) {
            std::this_thread::sleep_for(std::chrono::milliseconds(25));
            v = read_int16(*c, "D8");
        }
        // Counting on from the client's 20000 (not from where it was before the write).
        EXPECT_GT(v, 20000);
        EXPECT_LT(v, 20000 + 5000);
    }
}

// A plant whose CPU Units compute on finsd's one scenario thread: every unit's ticks go
// through it, each with its own scenario time, and a pause settles the one in flight.
TEST(ScenarioRun, APlantsUnitsShareTheScenarioThread) {
    ScratchDir dir("scenario-plant-thread");
    const std::string socket = (dir.path() / "ctl.sock").string();
    std::string config = "log_level = \"warn\"\n";
    for (int i = 1; i <= 3; ++i)
        config += "[[plc]]\nname = \"m" + std::to_string(i) +
                  "\"\n[[plc.ethernet]]\nnetwork = 1\nbind = \"127.0.1." + std::to_string(i) +
                  "\"\n[plc.scenario]\ntick_ms = 10\ncompute = \"thread\"\n"
                  "[[plc.scenario.signal]]\naddress = \"D8\"\nkind = \"counter\"\n"
                  "input = \"1\"\nrate = 100\n";
    const auto file = dir.write("plant.toml", config);
    Finsd d({"--config", file, "--control", socket});
    ASSERT_TRUE(d.started()) << d.result().err;
    const auto status = [&](int i) {
        const auto r = ctl(socket, {"--plc", "m" + std::to_string(i), "scenario", "status"});
        EXPECT_EQ(r.exit_code, 0) << r.err;
        return Json::parse(r.out, nullptr, false)["scenario"];
    };
    for (int i = 1; i <= 3; ++i) {
        std::uint64_t ticks = 0;
        for (int k = 0; k < 200 && ticks < 10; ++k) {
            std::this_thread::sleep_for(std::chrono::milliseconds(25));
            ticks = status(i)["ticks"].get<std::uint64_t>();
        }
        EXPECT_GE(ticks, 10u) << "m" << i;
        EXPECT_GE(status(i)["writes"].get<std::uint64_t>(), 10u) << "m" << i;
    }
    ASSERT_EQ(ctl(socket, {"--plc", "m2", "scenario", "pause"}).exit_code, 0);
    const auto paused = status(2)["ticks"].get<std::uint64_t>();
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
    EXPECT_EQ(status(2)["ticks"].get<std::uint64_t>(), paused);
    EXPECT_TRUE(status(2)["paused"].get<bool>());
}

}  // namespace
}  // namespace fins::test
