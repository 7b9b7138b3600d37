// Each [[plc]] of a plant takes a memory table of its own (README "A plant of several
// networks"): finsd writes it into that CPU Unit at start, and refuses an entry the
// CPU Unit's model cannot hold (exit 2, naming the entry).
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "fins/address.hpp"
#include "finsd_run.hpp"

namespace fins::test {
namespace {

// Two CPU Units, one Ethernet unit each, on loopback addresses no other test binds.
std::string plant(const std::string& b_memory) {
    return R"(
[[plc]]
name = "line-a"
  [plc.memory]
  "D100" = [11, 12]
  "W3.04" = true
  [[plc.ethernet]]
  network = 1
  bind = "127.0.61.1"
  port = 9611
[[plc]]
name = "line-b"
profile = "cj1m"
)" + b_memory +
           R"(
  [[plc.ethernet]]
  network = 2
  bind = "127.0.62.1"
  port = 9611
)";
}

std::vector<std::uint16_t> words_at(const std::string& host, const std::string& address,
                                    std::uint16_t count) {
    ClientOptions o;
    o.host = host;
    o.port = 9611;
    o.timeout = std::chrono::milliseconds(3000);
    auto c = Client::connect(o);
    EXPECT_TRUE(c) << c.error().message();
    if (!c) return {};
    auto got = (*c)->read_words(*parse_address(address), count);
    EXPECT_TRUE(got) << got.error().message();
    return got ? *got : std::vector<std::uint16_t>{};
}

TEST(PlantMemory, EachCpuUnitStartsWithItsOwnMemoryTable) {
    ScratchDir dir("plant-memory");
    Finsd d(
        {"--config",
         dir.write("plant.toml", plant("memory = { \"D100\" = 21, \"D101\" = { int16 = -2 } }"))});
    ASSERT_TRUE(d.started()) << d.result().err;
    EXPECT_EQ(words_at("127.0.61.1", "D100", 2), (std::vector<std::uint16_t>{11, 12}));
    EXPECT_EQ(words_at("127.0.61.1", "W3", 1), std::vector<std::uint16_t>{0x0010});
    EXPECT_EQ(words_at("127.0.62.1", "D100", 2), (std::vector<std::uint16_t>{21, 0xFFFE}));
    EXPECT_EQ(words_at("127.0.62.1", "W3", 1), std::vector<std::uint16_t>{0});
}

TEST(PlantMemory, EntryTheCpuUnitCannotHoldIsRefusedWithItsName) {
    ScratchDir dir("plant-memory");
    // The CJ1M has no EM area: the entry is refused for line-b, naming it and the model.
    const auto file = dir.write("plant.toml", plant("memory = { \"E0_0\" = 1 }"));
    Finsd d({"--config", file});
    ASSERT_FALSE(d.started());
    EXPECT_EQ(d.result().exit_code, 2) << d.result().err;
    EXPECT_NE(d.result().err.find("plc[1].memory.\"E0_0\": "), std::string::npos) << d.result().err;
}

}  // namespace
}  // namespace fins::test
