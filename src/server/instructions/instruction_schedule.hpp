// Instructions a node runs by itself, at a fixed period ([[schedule]] in the config):
// what a ladder program with a timer and a Send/Rcv/SendCmd would do.
//
// Bounded: each entry has at most one instruction running; a tick that finds the
// previous one still running is skipped (counted), so a schedule never holds more
// instructions than it has entries, and the config allows at most 32 entries (the W596
// limit). Results are counted per entry; an error is logged when an entry starts
// failing or its error changes, and its recovery once (no log flood).
#pragma once

#include <chrono>
#include <cstdint>
#include <memory>
#include <vector>

#include <boost/asio/any_io_executor.hpp>
#include <boost/asio/steady_timer.hpp>

#include "server/instructions/network_instructions.hpp"
#include "transport/asio.hpp"

namespace fins::server {

struct ScheduledInstruction {
    std::chrono::milliseconds every{1000};
    InstructionRequest request;
};

inline constexpr std::size_t max_scheduled_instructions = max_instructions;
inline constexpr std::chrono::milliseconds min_schedule_period{10};

class InstructionSchedule {
  public:
    struct EntryCounters {
        std::uint64_t runs = 0;
        std::uint64_t done = 0;
        std::uint64_t errors = 0;
        std::uint64_t skipped = 0;  // ticks that found the previous instruction running
        std::uint16_t last_error_id = 0;
        std::uint16_t last_error_id_ex = 0;
    };

    InstructionSchedule(asio::any_io_executor executor, NetworkInstructions& engine,
                        std::vector<ScheduledInstruction> entries);
    ~InstructionSchedule();
    InstructionSchedule(const InstructionSchedule&) = delete;
    InstructionSchedule& operator=(const InstructionSchedule&) = delete;

    void start();
    void stop();
    [[nodiscard]] std::size_t size() const noexcept { return entries_.size(); }
    [[nodiscard]] const EntryCounters& counters(std::size_t entry) const;

  private:
    struct Entry;
    void arm(std::size_t entry);
    void tick(std::size_t entry);

    asio::any_io_executor executor_;
    NetworkInstructions& engine_;
    std::vector<std::unique_ptr<Entry>> entries_;
    std::shared_ptr<bool> alive_ = std::make_shared<bool>(true);
};

}  // namespace fins::server
