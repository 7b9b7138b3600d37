// A plant's state files (README "A plant of several networks"): a file refused for its
// content stops finsd (exit 3) naming the CPU Unit and the file; --reset-state moves it
// aside and starts that CPU Unit with empty retained memory, as for a single node.
#include <csignal>
#include <filesystem>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "fins/address.hpp"
#include "integration/support/finsd_process.hpp"

namespace fins::test {
namespace {

namespace fs = std::filesystem;

bool has(const std::string& text, const std::string& part) {
    return text.find(part) != std::string::npos;
}

std::unique_ptr<Client> connect() {
    ClientOptions o;
    o.host = "127.0.63.1";
    o.port = 9611;
    o.timeout = std::chrono::milliseconds(3000);
    auto c = Client::connect(o);
    EXPECT_TRUE(c) << c.error().message();
    return c ? std::move(*c) : nullptr;
}

// D0 of the plant's CPU Unit; 0xFFFF when it cannot be read.
std::uint16_t d0() {
    auto c = connect();
    if (!c) return 0xFFFF;
    const auto words = c->read_words(*parse_address("D0"), 1);
    EXPECT_TRUE(words) << words.error().message();
    return words && words->size() == 1 ? (*words)[0] : 0xFFFF;
}

TEST(PlantStateFile, RefusedFileNamesTheCpuUnitAndResetStateMovesItAside) {
    ScratchDir dir("plant-state");
    const fs::path data = dir.path() / "kept";
    const fs::path file = data / "finsd.state";
    const auto config = dir.write("plant.toml", R"(
[[plc]]
name = "kept"
data_dir = ")" + data.string() + R"("
  [[plc.ethernet]]
  network = 1
  bind = "127.0.63.1"
  port = 9611
)");
    {
        Finsd d({"--config", config});
        ASSERT_TRUE(d.started()) << d.result().err;
        auto c = connect();
        ASSERT_NE(c, nullptr);
        ASSERT_TRUE(c->write_words(*parse_address("D0"), std::vector<std::uint16_t>{0x1234}));
        c.reset();
        EXPECT_EQ(d.stop().exit_code, 0);
    }
    {  // A SIGKILL leaves no checksums: the next start says so, naming the CPU Unit.
        Finsd killed({"--config", config});
        ASSERT_TRUE(killed.started()) << killed.result().err;
        EXPECT_EQ(killed.stop(SIGKILL).exit_code, 128 + SIGKILL);
        Finsd d({"--config", config});
        ASSERT_TRUE(d.started()) << d.result().err;
        EXPECT_EQ(d0(), 0x1234);
        const auto stopped = d.stop();
        EXPECT_TRUE(has(stopped.err, "plc \"kept\": " + file.string() + " was not stopped cleanly"))
            << stopped.err;
    }
    fs::resize_file(file, 0);
    Finsd refused({"--config", config});
    ASSERT_FALSE(refused.started());
    EXPECT_EQ(refused.result().exit_code, 3);
    const std::string& err = refused.result().err;
    EXPECT_TRUE(has(err, "plc \"kept\": " + file.string() + ": ")) << err;
    EXPECT_TRUE(has(err, "--reset-state")) << err;
    EXPECT_EQ(fs::file_size(file), 0u);  // never replaced by itself

    Finsd reset({"--config", config, "--reset-state"});
    ASSERT_TRUE(reset.started()) << reset.result().err;
    EXPECT_EQ(d0(), 0);
    const auto stopped = reset.stop();
    EXPECT_EQ(stopped.exit_code, 0);
    EXPECT_TRUE(has(stopped.err, "--reset-state moved it to")) << stopped.err;
    int aside = 0;
    for (const auto& e : fs::directory_iterator(data))
        if (e.path().filename().string().rfind("finsd.state.replaced-", 0) == 0) ++aside;
    EXPECT_EQ(aside, 1);
    EXPECT_GT(fs::file_size(file), 4096u);
}

// What a plant says about a CPU Unit's state file reaches the operator at every log level,
// as a single node's does (they went through the log and vanished at --log-level error or
// off), and a file of another profile names it (W342's CPU Units differ in areas and sizes).
TEST(PlantStateFile, SaidAtEveryLogLevelAndAnotherProfilesFileIsNamed) {
    ScratchDir dir("plant-state-quiet");
    const fs::path data = dir.path() / "unit";
    const fs::path file = data / "finsd.state";
    const auto plant = [&](const std::string& profile) {
        return dir.write(profile + ".toml", R"(
[[plc]]
name = "unit"
profile = ")" + profile + R"("
data_dir = ")" + data.string() + R"("
  [[plc.ethernet]]
  network = 1
  bind = "127.0.63.2"  # its own: the test above binds .1
  port = 9611
)");
    };
    const auto cs1h = plant("cs1h");
    FinsdOptions quiet;
    quiet.log_level = "error";
    {
        Finsd killed({"--config", cs1h}, quiet);
        ASSERT_TRUE(killed.started()) << killed.result().err;
        EXPECT_EQ(killed.stop(SIGKILL).exit_code, 128 + SIGKILL);
        Finsd d({"--config", cs1h}, quiet);
        ASSERT_TRUE(d.started()) << d.result().err;
        const auto stopped = d.stop();
        EXPECT_EQ(stopped.exit_code, 0);
        EXPECT_TRUE(has(stopped.err, "finsd: warning: plc \"unit\": " + file.string() +
                                         " was not stopped cleanly"))
            << stopped.err;
    }
    FinsdOptions off;
    off.log_level = "off";
    Finsd other({"--config", plant("cj2h")}, off);
    ASSERT_FALSE(other.started());
    EXPECT_EQ(other.result().exit_code, 3);
    const std::string& err = other.result().err;
    EXPECT_TRUE(has(err, "plc \"unit\": " + file.string() + ": ")) << err;
    EXPECT_TRUE(has(err, "the file is for profile 'cs1h', this CPU Unit runs 'cj2h'")) << err;
    EXPECT_TRUE(has(err, "--reset-state")) << err;
}

}  // namespace
}  // namespace fins::test
