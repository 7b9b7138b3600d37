// A scenario's end_code fault covers every memory area command that names an address in
// the faulted area (issue 26 point 3): 01 01 and 01 02 on words and bits, every element
// of 01 04, 01 03 FILL, the source or the destination of 01 05; several areas at once.
// Through the Dispatcher with a FaultHook holding the scenario's TransportFaults.
#include <gtest/gtest.h>

#include <chrono>

#include "scenario/scenario.hpp"
#include "server/frame_builder.hpp"
#include "server/scenario/fault_hook.hpp"

namespace fins::test {
namespace {

class AreaFaults final : public server::FaultHook {
  public:
    scenario::TransportFaults faults;

    bool offline() const noexcept override { return false; }
    bool silent() noexcept override { return false; }
    std::uint16_t area_end_code(const MemoryAddress& address) const noexcept override {
        return faults.end_code_for(address);
    }
    std::chrono::milliseconds latency() const noexcept override { return {}; }
    void send_later(Bytes, server::Completion) override {}
};

// D answers 1101 and W 2101 (two areas at once, as two overlapping events leave them).
struct Faulted : ::testing::Test {
    Faulted() {
        hook.faults.areas.push_back({Region::dm, 0, 0x1101});
        hook.faults.areas.push_back({Region::work, 0, 0x2101});
        h.dispatcher.attach_faults(&hook);
    }
    // The end code as the two bytes of the response (after header and command code).
    std::string end_code_bytes(std::string_view command) {
        const auto reply = h.send(command);
        if (reply.frame.size() < 14) return "short";
        return to_hex(Bytes(reply.frame.data() + 12, 2));
    }
    Harness h;
    AreaFaults hook;
};

TEST_F(Faulted, WordAndBitReadsAndWritesAnswerTheAreasEndCode) {
    EXPECT_EQ(end_code_bytes("0101 82000A00 0001"), "11 01");       // D word read
    EXPECT_EQ(end_code_bytes("0102 82000A00 0001 1234"), "11 01");  // D word write
    EXPECT_EQ(end_code_bytes("0101 B1000300 0001"), "21 01");       // W word read
    EXPECT_EQ(end_code_bytes("0101 31000304 0001"), "21 01");       // W bit read
    EXPECT_EQ(end_code_bytes("0102 31000304 0001 01"), "21 01");    // W bit write
    EXPECT_EQ(end_code_bytes("0102 02000A03 0001 01"), "11 01");    // D bit write (CV)
    EXPECT_EQ(h.memory().words(Region::work)[3], 0);                // nothing written
    EXPECT_EQ(h.memory().words(Region::dm)[10], 0);
    // Another area is served as usual.
    EXPECT_EQ(end_code_bytes("0101 B0000300 0001"), "00 00");
    EXPECT_EQ(end_code_bytes("0102 30000304 0001 01"), "00 00");
}

TEST_F(Faulted, FillAnswersTheEndCodeAndFillsNothing) {
    EXPECT_EQ(end_code_bytes("0103 82000000 0004 ABCD"), "11 01");
    EXPECT_EQ(h.memory().words(Region::dm)[0], 0);
    EXPECT_EQ(end_code_bytes("0103 B0000000 0004 ABCD"), "00 00");
    EXPECT_EQ(h.memory().words(Region::cio)[3], 0xABCD);
}

TEST_F(Faulted, MultipleReadAnswersTheEndCodeOfAnyFaultedElement) {
    // CIO, then D: the second element is faulted.
    EXPECT_EQ(end_code_bytes("0104 B0000000 82000000"), "11 01");
    // W bit as the only faulted element, after two healthy ones.
    EXPECT_EQ(end_code_bytes("0104 B0000000 B2000000 31000001"), "21 01");
    EXPECT_EQ(end_code_bytes("0104 B0000000 B2000000"), "00 00");
}

TEST_F(Faulted, TransferAnswersTheEndCodeForTheSourceOrTheDestination) {
    h.memory().words(Region::cio)[0] = 0x4242;
    EXPECT_EQ(end_code_bytes("0105 82000000 B0000A00 0001"), "11 01");  // source in D
    EXPECT_EQ(end_code_bytes("0105 B0000000 B1000000 0001"), "21 01");  // destination in W
    EXPECT_EQ(h.memory().words(Region::work)[0], 0);
    EXPECT_EQ(end_code_bytes("0105 B0000000 B2000000 0001"), "00 00");  // CIO -> H
    EXPECT_EQ(h.memory().words(Region::holding)[0], 0x4242);
}

TEST_F(Faulted, WithoutAnAreaFaultEveryCommandIsServed) {
    hook.faults.areas.clear();
    EXPECT_EQ(end_code_bytes("0101 82000A00 0001"), "00 00");
    EXPECT_EQ(end_code_bytes("0102 31000304 0001 01"), "00 00");
    EXPECT_EQ(end_code_bytes("0104 B0000000 82000000"), "00 00");
    EXPECT_EQ(end_code_bytes("0103 82000000 0001 0001"), "00 00");
    EXPECT_EQ(end_code_bytes("0105 82000000 B1000000 0001"), "00 00");
}

}  // namespace
}  // namespace fins::test
