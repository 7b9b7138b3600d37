// examples/three-networks.toml runs as is: a client at 127.0.1.1:9600 (router-a on
// network 1) reads and writes node 5 of network 3 (DNA 3, DA1 5, DA2 0) through two
// routers, over FINS/UDP and FINS/TCP.
#include <array>
#include <filesystem>

#include <gtest/gtest.h>

#include "fins/address.hpp"
#include "integration/support/finsd_process.hpp"

namespace fins::test {
namespace {

TEST(PlantExample, ThreeNetworksRunsAsIsAndReachesNode3_5) {
    const auto file = std::filesystem::path(FINS_SOURCE_DIR) / "examples" / "three-networks.toml";
    // As the README runs it: without --port (which would give its units another port).
    Finsd d({"--config", file.string()}, {.port = std::nullopt});
    ASSERT_TRUE(d.started()) << d.result().err;
    ASSERT_EQ(d.port(), 9600);
    for (const bool tcp : {false, true}) {
        ClientOptions o;
        o.host = "127.0.1.1";
        o.port = 9600;
        o.protocol = tcp ? ClientOptions::Protocol::tcp : ClientOptions::Protocol::udp;
        o.destination = {3, 5, 0};
        o.timeout = std::chrono::milliseconds(3000);
        auto c = Client::connect(o);
        ASSERT_TRUE(c) << c.error().message();
        const std::array<std::uint16_t, 2> words{0x0305, static_cast<std::uint16_t>(tcp)};
        ASSERT_TRUE((*c)->write_words(*parse_address("D200"), words));
        const auto got = (*c)->read_words(*parse_address("D200"), 2);
        ASSERT_TRUE(got) << got.error().message();
        EXPECT_EQ(*got, std::vector<std::uint16_t>(words.begin(), words.end()));
    }
}

}  // namespace
}  // namespace fins::test
