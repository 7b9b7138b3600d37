// Retained memory survives SIGKILL: finsd with --data-dir acknowledges thousands of
// writes to D, H, EM and counter words, is killed without a chance to flush, and a new
// finsd on the same directory reads every acknowledged value back (and warns that the
// file was not stopped cleanly). CIO, W, timers and the cleared Auxiliary Area words
// start at zero again.
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <fstream>
#include <functional>
#include <iostream>
#include <string>
#include <thread>
#include <vector>

#include <fmt/format.h>
#include <gtest/gtest.h>

#include "integration/support/finsd_process.hpp"

namespace fins::test {
namespace {

struct Word {
    std::string address;
    std::uint16_t value;
};

// Distinct non-zero values: 40503 is odd, so i -> i * 40503 + 1 is a bijection mod 2^16.
std::uint16_t value_of(std::size_t i) {
    return static_cast<std::uint16_t>(i * 40503U + 1U);
}

// 5,000 distinct retained words: D0-1999, H0-499, 80 words in each of the 25 EM banks,
// C0-499.
std::vector<Word> retained_words() {
    std::vector<std::string> addresses;
    for (int i = 0; i < 2000; ++i)
        addresses.push_back(fmt::format("D{}", i));
    for (int i = 0; i < 500; ++i)
        addresses.push_back(fmt::format("H{}", i));
    for (int bank = 0; bank < 25; ++bank)
        for (int i = 0; i < 80; ++i)
            addresses.push_back(fmt::format("E{:X}_{}", bank, i * 409));  // banks in hex
    for (int i = 0; i < 500; ++i)
        addresses.push_back(fmt::format("C{}", i));
    std::vector<Word> words;
    for (std::size_t i = 0; i < addresses.size(); ++i)
        words.push_back({addresses[i], value_of(i)});
    return words;
}

// 01 02 parameters writing `value` to one word.
std::vector<std::uint8_t> write_params(const std::string& text, std::uint16_t value) {
    const auto m = to_memory_address(addr(text), Access::word);
    EXPECT_TRUE(m.has_value()) << text;
    const auto a = m.value_or(MemoryAddress{});
    return {a.area_code,
            static_cast<std::uint8_t>(a.word >> 8),
            static_cast<std::uint8_t>(a.word),
            0x00,
            0x00,
            0x01,
            static_cast<std::uint8_t>(value >> 8),
            static_cast<std::uint8_t>(value)};
}

const CommandCode memory_write{0x01, 0x02};

TEST(Sigkill, AcknowledgedWritesSurviveAndClearedAreasStartAtZero) {
    ScratchDir dir("sigkill");
    const std::string data = (dir.path() / "data").string();
    const auto words = retained_words();
    ASSERT_EQ(words.size(), 5000u);
    std::size_t acknowledged = 0;
    {
        Finsd d({"--profile", "cj2h", "--data-dir", data});
        ASSERT_TRUE(d.started()) << d.result().err;
        auto c = d.client(true);
        ASSERT_NE(c, nullptr);
        for (const auto& w : words)
            if (end_code(*c, memory_write, write_params(w.address, w.value)) == 0) ++acknowledged;
        // Cleared areas, and A: A448 cleared, A510 (Startup Time) retained.
        const std::vector<std::uint16_t> marks(100, 0xA5A5);
        for (const char* cleared : {"CIO0", "W0", "T0"})
            ASSERT_TRUE(c->write_words(addr(cleared), marks).has_value()) << cleared;
        ASSERT_TRUE(c->write_words(addr("A448"), std::vector<std::uint16_t>(10, 0x0448)));
        ASSERT_TRUE(c->write_words(addr("A510"), std::vector<std::uint16_t>(11, 0x0510)));
        const auto killed = d.stop(SIGKILL);  // no flush, no destructor
        EXPECT_EQ(killed.exit_code, 128 + SIGKILL);
    }
    EXPECT_EQ(acknowledged, words.size());

    Finsd d({"--profile", "cj2h", "--data-dir", data});
    ASSERT_TRUE(d.started()) << d.result().err;
    auto c = d.client(true);
    ASSERT_NE(c, nullptr);
    std::size_t lost = 0;
    const auto check_run = [&](const std::string& first, std::size_t from, std::size_t count) {
        const auto got = words_of(*c, first, count);
        ASSERT_EQ(got.size(), count) << first;
        for (std::size_t i = 0; i < count; ++i)
            if (got[i] != words[from + i].value) ++lost;
    };
    check_run("D0", 0, 2000);
    check_run("H0", 2000, 500);
    for (std::size_t i = 2500; i < 4500; ++i) {  // EM words are spread out: one by one
        const auto got = words_of(*c, words[i].address, 1);
        if (got.size() != 1 || got[0] != words[i].value) ++lost;
    }
    check_run("C0", 4500, 500);
    std::cout << "[ sigkill ] acknowledged " << acknowledged << " writes, lost " << lost << "\n";
    RecordProperty("acknowledged", static_cast<int>(acknowledged));
    RecordProperty("lost", static_cast<int>(lost));
    EXPECT_EQ(lost, 0u);

    for (const char* cleared : {"CIO0", "W0", "T0"})
        EXPECT_EQ(words_of(*c, cleared, 100), std::vector<std::uint16_t>(100, 0)) << cleared;
    EXPECT_EQ(words_of(*c, "A448", 10), std::vector<std::uint16_t>(10, 0));
    EXPECT_EQ(words_of(*c, "A510", 11), std::vector<std::uint16_t>(11, 0x0510));

    // The start after the kill said that the data's checksums could not be checked; a
    // start after a clean stop (SIGTERM) checks them and says nothing.
    const auto stopped = d.stop();
    EXPECT_EQ(stopped.exit_code, 0);
    EXPECT_NE(stopped.err.find("was not stopped cleanly"), std::string::npos) << stopped.err;
    // Its own control socket: under ctest -j another root finsd may hold the default
    // /run/finsd/finsd.sock, and that warning is not the one this checks for.
    Finsd again({"--profile", "cj2h", "--data-dir", data, "--control", data + "/ctl.sock"});
    ASSERT_TRUE(again.started()) << again.result().err;
    const auto clean = again.stop();
    EXPECT_EQ(clean.exit_code, 0);
    EXPECT_EQ(clean.err.find("warning"), std::string::npos) << clean.err;
}

// --durability power: the same guarantee through the fdatasync path (what it adds, the
// power-loss case, cannot be produced in a test; docs/benchmarks.md has its cost).
TEST(Sigkill, PowerDurabilityAcknowledgedWritesSurvive) {
    ScratchDir dir("sigkill");
    const std::string data = (dir.path() / "data").string();
    constexpr std::size_t total = 300;
    {
        Finsd d({"--profile", "cs1h", "--data-dir", data, "--durability", "power"});
        ASSERT_TRUE(d.started()) << d.result().err;
        auto c = d.client(false);
        ASSERT_NE(c, nullptr);
        for (std::size_t i = 0; i < total; ++i)
            ASSERT_EQ(end_code(*c, memory_write,
                               write_params(fmt::format("D{}", 20000 + i), value_of(i))),
                      0u);
        d.stop(SIGKILL);
    }
    Finsd d({"--profile", "cs1h", "--data-dir", data, "--durability", "power"});
    ASSERT_TRUE(d.started()) << d.result().err;
    auto c = d.client(false);
    ASSERT_NE(c, nullptr);
    const auto got = words_of(*c, "D20000", total);
    ASSERT_EQ(got.size(), total);
    for (std::size_t i = 0; i < total; ++i)
        EXPECT_EQ(got[i], value_of(i)) << i;
}

// SIGKILL while 32 writes are in flight: every write acknowledged before the kill is
// in the state file afterwards.
TEST(Sigkill, KillWithWritesInFlightLosesNoAcknowledgedWrite) {
    ScratchDir dir("sigkill");
    const std::string data = (dir.path() / "data").string();
    constexpr std::size_t total = 4000;
    constexpr std::size_t kill_after = 2500;
    constexpr std::size_t window = 32;
    std::vector<std::vector<std::uint8_t>> params;
    for (std::size_t i = 0; i < total; ++i)
        params.push_back(write_params(fmt::format("D{}", 10000 + i), value_of(i)));
    std::vector<bool> acked(total, false);
    std::size_t acknowledged = 0;
    {
        Finsd d({"--profile", "cs1h", "--data-dir", data});
        ASSERT_TRUE(d.started()) << d.result().err;
        auto c = d.client(true);
        ASSERT_NE(c, nullptr);
        std::size_t next = 0;
        bool killed = false;
        std::function<void()> send_next = [&] {
            if (killed || next >= total) return;
            const std::size_t i = next++;
            c->async_send_raw(memory_write, params[i], [&, i](Result<RawResponse> r) {
                if (r && r->code.ok()) {
                    acked[i] = true;
                    if (++acknowledged == kill_after) {
                        ::kill(d.pid(), SIGKILL);
                        killed = true;
                    }
                }
                send_next();
            });
        };
        for (std::size_t k = 0; k < window; ++k)
            send_next();
        c->run();
        EXPECT_TRUE(killed);
        d.stop(SIGKILL);  // reap
    }
    EXPECT_GE(acknowledged, kill_after);

    Finsd d({"--profile", "cs1h", "--data-dir", data});
    ASSERT_TRUE(d.started()) << d.result().err;
    auto c = d.client(true);
    ASSERT_NE(c, nullptr);
    const auto got = words_of(*c, "D10000", total);
    ASSERT_EQ(got.size(), total);
    std::size_t lost = 0;
    for (std::size_t i = 0; i < total; ++i)
        if (acked[i] && got[i] != value_of(i)) ++lost;
    std::cout << "[ sigkill ] in flight: acknowledged " << acknowledged << " writes, lost " << lost
              << "\n";
    EXPECT_EQ(lost, 0u);
}

}  // namespace
}  // namespace fins::test

namespace fins::test {
namespace {

// True while `pid` runs (a zombie, or no process at all, is not running).
bool running(pid_t pid) {
    std::ifstream stat("/proc/" + std::to_string(pid) + "/stat");
    std::string line;
    if (!std::getline(stat, line)) return false;
    const auto paren = line.rfind(')');
    return paren != std::string::npos && paren + 2 < line.size() && line[paren + 2] != 'Z';
}

// A test binary that dies abruptly (no destructor runs) takes its Child processes with
// it: an orphaned finsd once held a port and broke the next run (process.hpp).
TEST(Sigkill, ChildOfATestBinaryThatDiesIsKilledToo) {
    int fds[2];
    ASSERT_EQ(::pipe(fds), 0);
    const pid_t binary = ::fork();
    ASSERT_GE(binary, 0);
    if (binary == 0) {
        ::close(fds[0]);
        auto* child = new Child({"/bin/sleep", "30"});  // never destroyed: we die first
        const pid_t pid = child->pid();
        if (::write(fds[1], &pid, sizeof pid) != sizeof pid) ::_exit(1);
        ::_exit(0);
    }
    ::close(fds[1]);
    pid_t grandchild = -1;
    const auto got = ::read(fds[0], &grandchild, sizeof grandchild);
    ::close(fds[0]);
    ::waitpid(binary, nullptr, 0);
    ASSERT_EQ(got, static_cast<ssize_t>(sizeof grandchild));
    ASSERT_GT(grandchild, 0);
    bool gone = false;
    for (int i = 0; i < 500 && !gone; ++i) {  // at most 5 s
        gone = !running(grandchild);
        if (!gone) std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
    if (!gone) ::kill(grandchild, SIGKILL);  // the test failed: do not leave it behind
    EXPECT_TRUE(gone) << "the Child outlived its test binary";
}

}  // namespace
}  // namespace fins::test
