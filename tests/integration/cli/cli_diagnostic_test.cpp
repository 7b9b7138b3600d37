// The diagnostic verbs of `fins` (status, messages, fal, access, error-clear, error-log,
// access-log, force, force-cancel) and `finsd ctl`, run as a user runs them against a
// finsd child started with --control: output, JSON and exit codes (0 ok, 2 usage,
// 3 transport / no control socket, 4 end code).
#include <unistd.h>

#include <filesystem>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "integration/support/finsd_process.hpp"

namespace fins::test {
namespace {

using Json = nlohmann::json;

class CliDiagnostic : public FinsdTest {
  protected:
    CliDiagnostic() : FinsdTest({}, true) {}
    RunResult ctl(const std::vector<std::string>& args) { return test::ctl(socket(), args); }
    void ctl_ok(std::vector<std::string> args) {
        auto r = ctl(args);
        ASSERT_EQ(r.exit_code, 0) << r.err;
        ASSERT_EQ(r.out, "{\"ok\":true}\n");
    }
};

TEST_F(CliDiagnostic, StatusAfterInjectingBatteryFalAndMessage) {
    auto idle = fins({"status"});
    ASSERT_EQ(idle.exit_code, 0) << idle.err;
    EXPECT_EQ(idle.out,
              "mode            run (running)\nbattery         present\nfatal errors    0000\n"
              "non-fatal       0000\nerror code      0000\nmessages        none\n");
    ctl_ok({"battery-error", "on"});
    ctl_ok({"fal", "5", "LOW OIL"});
    ctl_ok({"message", "3", "TANK FULL"});
    auto s = fins({"status"});
    ASSERT_EQ(s.exit_code, 0) << s.err;
    EXPECT_EQ(s.out,
              "mode            run (running)\nbattery         present\nfatal errors    0000\n"
              "non-fatal       8010  FAL error, battery error\nerror code      4105  FAL 5\n"
              "messages        MSG 3\nerror message   \"LOW OIL\"\n");
    auto j = fins({"status", "--json"});
    ASSERT_EQ(j.exit_code, 0) << j.err;
    const auto doc = Json::parse(j.out);
    EXPECT_EQ(doc["non_fatal_errors"], "8010");
    EXPECT_EQ(doc["non_fatal"], Json::parse(R"(["FAL error","battery error"])"));
    EXPECT_EQ(doc["messages"], Json::parse("[3]"));
    EXPECT_EQ(doc["error_message"], "LOW OIL");
    // The battery flag rides on every end code (W342 5-1-3): raw shows it.
    auto raw = fins({"raw", "0101", "82000000", "0001"});
    EXPECT_EQ(raw.exit_code, 0) << raw.err;
    EXPECT_NE(raw.out.find("end code 0040"), std::string::npos) << raw.out;
    EXPECT_NE(raw.out.find("[non-fatal CPU error]"), std::string::npos) << raw.out;
}

TEST_F(CliDiagnostic, FalsStopsTheCpuAndOnlyProgramModeClearsIt) {
    ctl_ok({"fals", "2", "HALT"});
    auto s = fins({"status", "--json"});
    ASSERT_EQ(s.exit_code, 0) << s.err;
    const auto doc = Json::parse(s.out);
    EXPECT_EQ(doc["running"], false);
    EXPECT_EQ(doc["mode"], "run");
    EXPECT_EQ(doc["fatal_errors"], "0040");
    EXPECT_EQ(doc["error_code"], "C102");
    auto refused = fins({"error-clear", "all"});
    EXPECT_EQ(refused.exit_code, 4);
    EXPECT_NE(refused.err.find("2206"), std::string::npos) << refused.err;
    ASSERT_EQ(fins({"stop"}).exit_code, 0);
    auto cleared = fins({"error-clear", "all"});
    EXPECT_EQ(cleared.exit_code, 0) << cleared.err;
    EXPECT_EQ(cleared.out, "cleared all errors (FFFF)\n");
    EXPECT_EQ(Json::parse(fins({"status", "--json"}).out)["error_code"], "0000");
    EXPECT_EQ(fins({"error-clear", "1234"}).exit_code, 4);  // 110C
    EXPECT_EQ(fins({"error-clear", "xyz"}).exit_code, 2);
}

TEST_F(CliDiagnostic, MessagesAndFalRead) {
    ctl_ok({"message", "1", "PUMP ON"});
    ctl_ok({"message", "6", "DOOR OPEN"});
    ctl_ok({"fal", "9", "LOW OIL"});
    auto m = fins({"messages", "1", "6"});
    ASSERT_EQ(m.exit_code, 0) << m.err;
    EXPECT_EQ(m.out, "MSG 1  PUMP ON\nMSG 6  DOOR OPEN\n");
    ASSERT_EQ(fins({"messages", "--clear", "1"}).exit_code, 0);
    EXPECT_EQ(fins({"messages", "1"}).out, "MSG 1\n");
    auto j = fins({"messages", "--json"});
    EXPECT_EQ(Json::parse(j.out)["items"].size(), 8u);
    EXPECT_EQ(fins({"messages", "8"}).exit_code, 2);
    auto f = fins({"fal", "9"});
    EXPECT_EQ(f.exit_code, 0) << f.err;
    EXPECT_EQ(f.out, "FAL/FALS 9  \"LOW OIL\"\n");
    EXPECT_EQ(Json::parse(fins({"fal", "10", "--json"}).out)["error_message"], "");
}

TEST_F(CliDiagnostic, AccessRightAcrossTwoSourceNodes) {
    auto a = fins({"--source", "0.10.0", "access", "acquire"});
    ASSERT_EQ(a.exit_code, 0) << a.err;
    EXPECT_EQ(a.out, "access right acquired\n");
    auto refused = fins({"--source", "0.11.0", "access", "acquire", "--json"});
    EXPECT_EQ(refused.exit_code, 4);
    const auto doc = Json::parse(refused.out);
    EXPECT_EQ(doc["error"]["end_code"], "3001");
    // The refusal names the holder (its 3 bytes, W342 5-3-24) and what helps.
    const std::string held =
        "node 0.10.0 holds the access right (0C 01): `fins access force` takes it over (0C 02), "
        "or the holder gives it back (`fins --source 0.10.0 access release` sends its 0C 03)";
    EXPECT_EQ(doc["error"]["holder"], "0.10.0");
    EXPECT_EQ(doc["error"]["hint"], held);
    EXPECT_EQ(fins({"--source", "0.11.0", "access", "acquire"}).err,
              "fins: access right held by 0.10.0 (network.node.unit): 3001\nfins: " + held + "\n");
    // 21 03: refused while another node holds the access right (5-3-29 and the 0C 01 /
    // 0C 02 pages decide against 5-1-2's OK). The 3001 carries no holder: fins asks with
    // an 0C 01, whose refusal names it.
    auto clear = fins({"--source", "0.11.0", "error-log", "--clear", "--json"});
    EXPECT_EQ(clear.exit_code, 4) << clear.err;
    EXPECT_EQ(Json::parse(clear.out)["error"]["end_code"], "3001");
    EXPECT_EQ(Json::parse(clear.out)["error"]["hint"], held);
    const auto clear_text = fins({"--source", "0.11.0", "error-log", "--clear"});
    EXPECT_EQ(clear_text.err.substr(clear_text.err.find('\n') + 1), "fins: " + held + "\n")
        << clear_text.err;
    EXPECT_EQ(fins({"--source", "0.11.0", "access-log", "--clear"}).exit_code, 4);  // 21 41
    EXPECT_EQ(fins({"--source", "0.11.0", "access", "force"}).exit_code, 0);
    EXPECT_EQ(fins({"--source", "0.10.0", "access", "acquire"}).exit_code, 4);
    EXPECT_EQ(fins({"--source", "0.10.0", "access", "release"}).out, "access right released\n");
    EXPECT_EQ(fins({"--source", "0.10.0", "access", "acquire"}).exit_code, 0);
    EXPECT_EQ(fins({"access", "steal"}).exit_code, 2);
}

TEST_F(CliDiagnostic, ErrorLogAndAccessLog) {
    auto empty = fins({"error-log"});
    EXPECT_EQ(empty.exit_code, 0) << empty.err;  // 1104 with no records is success
    EXPECT_EQ(empty.out, "error log empty\n");
    ctl_ok({"error", "0203"});
    ctl_ok({"fal", "1"});
    auto log = fins({"error-log", "--json"});
    ASSERT_EQ(log.exit_code, 0) << log.err;
    auto doc = Json::parse(log.out);
    EXPECT_EQ(doc["stored"], 2);
    EXPECT_EQ(doc["records"][0]["code"], "0203");
    EXPECT_EQ(doc["records"][0]["name"], "CPU Bus Unit error");
    EXPECT_EQ(doc["records"][1]["name"], "FAL 1");
    EXPECT_EQ(fins({"error-log", "--clear"}).out, "error log cleared\n");
    EXPECT_EQ(fins({"error-log"}).out, "error log empty\n");

    ASSERT_EQ(fins({"--source", "0.33.0", "write", "D0", "1"}).exit_code, 0);
    auto access = fins({"access-log", "--json"});
    ASSERT_EQ(access.exit_code, 0) << access.err;
    doc = Json::parse(access.out);
    ASSERT_GE(doc["records"].size(), 1u);
    bool found = false;
    for (const auto& r : doc["records"])
        found = found || (r["source"] == "0.33.0" && r["command"] == "0102" &&
                          r["name"] == "MEMORY AREA WRITE");
    EXPECT_TRUE(found) << access.out;
    EXPECT_EQ(fins({"access-log", "--clear"}).out, "write access log cleared\n");
    doc = Json::parse(fins({"access-log", "--json"}).out);
    ASSERT_EQ(doc["records"].size(), 1u);  // the 21 41 itself
    EXPECT_EQ(doc["records"][0]["command"], "2141");
}

TEST_F(CliDiagnostic, ForceSetReleaseAndCancel) {
    auto run_mode = fins({"force", "set", "CIO10.13"});
    EXPECT_EQ(run_mode.exit_code, 4);  // 2206: not in RUN mode
    ASSERT_EQ(fins({"stop"}).exit_code, 0);
    auto set = fins({"force", "set", "CIO10.13", "T5", "W0.1"});
    ASSERT_EQ(set.exit_code, 0) << set.err;
    EXPECT_EQ(set.out, "force set: CIO10.13 T5 W0.01\n");
    ASSERT_EQ(fins({"write", "CIO10.13", "0"}).exit_code, 0);
    EXPECT_EQ(fins({"read", "CIO10.13"}).out, "CIO10.13  1\n");  // forced stays ON
    EXPECT_EQ(fins({"read", "T5", "--as", "bits"}).out, "T5  1\n");
    ASSERT_EQ(fins({"force", "release-off", "W0.1"}).exit_code, 0);
    EXPECT_EQ(fins({"read", "W0.1"}).out, "W0.01  0\n");
    auto cancel = fins({"force-cancel"});
    EXPECT_EQ(cancel.exit_code, 0) << cancel.err;
    EXPECT_EQ(cancel.out, "all forced bits released\n");
    ASSERT_EQ(fins({"write", "CIO10.13", "0"}).exit_code, 0);
    EXPECT_EQ(fins({"read", "CIO10.13"}).out, "CIO10.13  0\n");
    auto bad = fins({"force", "set", "D100.1"});
    EXPECT_EQ(bad.exit_code, 2);
    EXPECT_NE(bad.err.find("cannot force"), std::string::npos) << bad.err;
    EXPECT_EQ(fins({"force", "wiggle", "CIO0.0"}).exit_code, 2);
}

TEST_F(CliDiagnostic, CtlVerbsAndExitCodes) {
    auto s = ctl({"status"});
    ASSERT_EQ(s.exit_code, 0) << s.err;
    EXPECT_EQ(Json::parse(s.out)["status"]["mode"], "run");
    ctl_ok({"mode", "monitor"});
    ctl_ok({"write-protect", "on"});
    EXPECT_EQ(fins({"write", "D0", "1"}).exit_code, 4);  // 2102
    ctl_ok({"write-protect", "off"});
    ctl_ok({"error", "80F0"});
    ctl_ok({"clear-errors", "80F0"});
    ctl_ok({"battery-error", "on"});
    ctl_ok({"clear-errors"});
    ctl_ok({"message", "2", "HELLO"});
    ctl_ok({"message", "2"});
    ctl_ok({"release-access"});
    ctl_ok({"send", R"({"cmd":"mode","mode":"run"})"});
    auto doc = Json::parse(ctl({"status"}).out)["status"];
    EXPECT_EQ(doc["mode"], "run");
    EXPECT_EQ(doc["end_code_flags"], "0000");
    EXPECT_TRUE(doc["messages"].empty());
    // Refused requests and usage errors: 2; no socket: 3.
    auto refused = ctl({"send", "not json"});
    EXPECT_EQ(refused.exit_code, 2);
    EXPECT_NE(refused.err.find("not JSON"), std::string::npos) << refused.err;
    EXPECT_EQ(ctl({"error", "1234"}).exit_code, 2);
    EXPECT_EQ(ctl({"fal", "0"}).exit_code, 2);
    EXPECT_EQ(ctl({"mode", "debug"}).exit_code, 2);
    EXPECT_EQ(ctl({"bogus"}).exit_code, 2);
    // No --socket: $FINSD_SOCKET (else the default path finsd uses too; issue 18).
    EXPECT_EQ(
        run({"/usr/bin/env", "FINSD_SOCKET=" + socket(), finsd_path, "ctl", "status"}).exit_code,
        0);
    auto gone = run({finsd_path, "ctl", "--socket", socket() + ".missing", "status"});
    EXPECT_EQ(gone.exit_code, 3);
    EXPECT_NE(gone.err.find("cannot connect"), std::string::npos) << gone.err;
}

}  // namespace
}  // namespace fins::test
