// [storage] durability = "power" (issue 6 item 6): every FINS write command that reaches
// its handler has the state file fdatasynced before its answer is built; reads and
// refused commands cost nothing, and the default ("process") never syncs.
#include <unistd.h>

#include <atomic>
#include <filesystem>
#include <memory>
#include <string>

#include <gtest/gtest.h>

#include "server/frame_builder.hpp"

namespace fins::test {
namespace {

namespace fs = std::filesystem;

class Durable : public ::testing::Test {
  protected:
    void SetUp() override {
        static std::atomic<int> n{0};
        dir_ = fs::temp_directory_path() /
               ("finskit-durable-" + std::to_string(::getpid()) + "-" + std::to_string(n++));
        fs::remove_all(dir_);
    }
    void TearDown() override { fs::remove_all(dir_); }

    std::unique_ptr<plc::Plc> plc_on_file(plc::Durability durability) {
        const auto profile = plc::cj2h();
        auto s = plc::Storage::open(dir_, profile.name, {durability});
        EXPECT_TRUE(s) << s.error().message();
        auto p = std::make_unique<plc::Plc>(profile, s ? std::move(*s) : nullptr);
        EXPECT_TRUE(p->storage().seal());
        return p;
    }
    std::uint16_t send(server::Dispatcher& d, std::string_view command_hex) {
        const auto frame = request_frame(command_hex);
        const auto n = d.handle(Bytes{frame.data(), frame.size()}, out_, {});
        Reply r;
        r.frame.assign(out_.begin(), out_.begin() + static_cast<std::ptrdiff_t>(n));
        return r.end_code();
    }

    fs::path dir_;
    std::array<std::uint8_t, max_frame_size> out_{};
};

TEST_F(Durable, PowerSyncsBeforeEachWriteAnswerNotForReads) {
    auto plc = plc_on_file(plc::Durability::power);
    server::Dispatcher d{*plc, server_node};
    EXPECT_EQ(send(d, "0102 82000000 0001 1234"), 0x0000);  // MEMORY AREA WRITE
    EXPECT_EQ(plc->storage().syncs(), 1u);
    EXPECT_EQ(send(d, "0101 82000000 0001"), 0x0000);  // MEMORY AREA READ
    EXPECT_EQ(send(d, "0501"), 0x0000);                // CPU UNIT DATA READ
    EXPECT_EQ(plc->storage().syncs(), 1u);
    EXPECT_EQ(send(d, "0103 82000000 0002 0000"), 0x0000);  // MEMORY AREA FILL
    EXPECT_EQ(plc->storage().syncs(), 2u);
    // Refused before the handler (network write protection): nothing changed, no sync.
    plc->set_network_write_protection(true);
    EXPECT_EQ(send(d, "0102 82000000 0001 1234"), 0x2102);
    EXPECT_EQ(plc->storage().syncs(), 2u);
}

// 09 20's row is a read (5-3-21, 5-3-23); its MESSAGE CLEAR variant is a write and is
// synced like every other write, its reads are not.
TEST_F(Durable, W342_5_3_22_MessageClearIsSyncedMessageReadIsNot) {
    auto plc = plc_on_file(plc::Durability::power);
    server::Dispatcher d{*plc, server_node};
    EXPECT_EQ(send(d, "0920 0083"), 0x0000);  // MESSAGE READ
    EXPECT_EQ(plc->storage().syncs(), 0u);
    EXPECT_EQ(send(d, "0920 4005"), 0x0000);  // MESSAGE CLEAR
    EXPECT_EQ(plc->storage().syncs(), 1u);
}

TEST_F(Durable, ProcessNeverSyncs) {
    auto plc = plc_on_file(plc::Durability::process);
    server::Dispatcher d{*plc, server_node};
    EXPECT_EQ(send(d, "0102 82000000 0001 1234"), 0x0000);
    EXPECT_EQ(plc->storage().syncs(), 0u);
}

}  // namespace
}  // namespace fins::test
