// A running scenario: the tags of a ScenarioDef bound to one CPU Unit's memory, computed
// tick by tick, and the events that fault them. No sockets, no clock of its own: the
// glue (src/server/scenario) calls tick() from a steady timer, or advance() for virtual
// time, and passes the host time only for what the CPU Unit stamps (error log, clock).
//
// Time: memory holds the tags at scenario time t = ticks() * tick_s. start() computes
// them at the start time (0) without moving it; each tick then moves time one tick on
// and computes at the new time. tick(), begin_tick() and advance() start a scenario that
// was not started first.
//
// One tick, in three phases:
//   begin_tick (on the thread that owns the CPU Unit):
//     1. time moves to t = (ticks() + 1) * tick_s; events whose duration ran out by t end
//        (an event is in force for at_s <= t < at_s + duration_s), events whose start
//        time has come start (value faults attach to their tag, unit faults change the
//        CPU Unit or transport());
//     2. the words the tags read and write are copied into the scenario's image, with
//        their forced-bit masks (the CPU Unit's input refresh);
//   compute (on any thread, when offloadable(): it touches the image and the
//   scenario's own state only, never the CPU Unit):
//     3. every tag, in dependency order (a tag after the tags its expressions read; a
//        cycle is a compile error), computes its value at t and writes it on the image
//        the way a FINS 01 02 write does: a forced bit keeps its forced state, exactly as
//        a ladder program cannot override it. Stateful kinds integrate over the tick that
//        just ended (t - tick_s to t, their input read at t); a tag with `when` has its
//        own clock, the ticks that ended with its `when` holding;
//   end_tick (on the owning thread again):
//     4. the words the tick changed are copied to memory (the output refresh), forced
//        bits kept; a word a client wrote since begin_tick keeps the client's value, and
//        a stateful tag adopts it on the next tick;
//     5. when anything was written, the FINS write access log gets one record from node
//        0.0.0 (the CPU Unit itself), so a client sees that the scenario wrote.
// tick() runs the three back to back. Words the image cannot hold (timers' and counters'
// completion flags, EM banks by number) are read and written through IoMemory during
// compute; a scenario with such a tag is not offloadable().
// Stateful kinds (random_walk, counter, totaliser, lag) keep their state in a double but
// adopt the memory's value when a client (or a force) changed the tag since the last
// write: an HMI writing 0 to a counter resets it.
//
// Determinism: time moves in whole ticks; every random draw comes from one Random seeded
// with `seed`, in tag order then event order. The same definition, seed and client writes
// at the same ticks give the same memory, byte for byte.
#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include <tl/expected.hpp>

#include "fins/memory_area.hpp"
#include "plc/io_memory.hpp"
#include "scenario/definition.hpp"

namespace fins::plc {
class Plc;
}

namespace fins::scenario {

struct CompileError {
    SourcePos pos;
    std::string message;
};

// Unit faults the transport applies (node offline, latency, drop fraction) and the
// dispatcher-level end-code faults. Read by the sessions on the io thread that ticks.
// Each is the combination of every event holding it (an active event, or a unit fault
// of duration 0, which stays): offline while any offline event is; latency and drop the
// largest of the active ones; an end code per area, several areas at once.
struct TransportFaults {
    // An area whose memory area commands (01 01-01 05, words and bits) answer end_code.
    // An area is a region of I/O memory (CIO, W, H, A, D, an EM bank, ...), whatever
    // code (word, bit, forced) names it.
    struct AreaFault {
        Region region = Region::dm;
        std::uint8_t em_bank = 0;
        std::uint16_t end_code = 0;
    };
    bool offline = false;
    std::uint32_t latency_ms = 0;
    double drop_fraction = 0.0;
    std::vector<AreaFault> areas;  // one per area; the newest event's end code on each

    // The end code of the area holding `address` (0: none, or not an I/O memory address).
    [[nodiscard]] std::uint16_t end_code_for(const MemoryAddress& address) const noexcept;
};

struct EventStatus {
    std::string name;
    std::string fault;
    bool active = false;
    double next_start_s = -1;  // -1: never again
};

struct Status {
    double time_s = 0;
    std::uint64_t ticks = 0;
    std::uint64_t writes = 0;          // tag writes since start
    std::uint64_t skipped_writes = 0;  // NaN/infinite results, when = false
    std::size_t tags = 0;
    std::vector<EventStatus> events;
};

class Scenario {
  public:
    static tl::expected<std::unique_ptr<Scenario>, CompileError> compile(ScenarioDef definition,
                                                                         plc::Plc& plc);
    ~Scenario();
    Scenario(const Scenario&) = delete;
    Scenario& operator=(const Scenario&) = delete;

    [[nodiscard]] const ScenarioDef& definition() const noexcept;
    // Computes the tags at the current time (0) without moving it, once: memory holds
    // f(0) before any tick. Later calls do nothing.
    void start(plc::TimePoint now) noexcept;
    [[nodiscard]] bool started() const noexcept;
    // For a scenario replacing `previous` (a reload), before its start(): it goes on at
    // previous's time (the same tick count with the same tick_s, else that time rounded
    // down to a whole tick), its start() computes the tags at that time with stateful
    // tags going on from the value memory holds, a `when` clock goes on for the tag of
    // the same address, and events are placed at that time: a one-shot event whose start
    // is past is not replayed, an every_s event next starts at its first time at or after
    // it. Nothing when this one started or `previous` did not.
    void continue_from(const Scenario& previous) noexcept;
    // One tick of tick_s. `now` stamps what the CPU Unit records (error log, clock jump).
    void tick(plc::TimePoint now) noexcept;
    // tick() in its three phases, for a caller that computes on another thread: between
    // begin_tick and end_tick the owning thread may serve requests and read status(), but
    // must not call anything else of this scenario (settle first).
    [[nodiscard]] bool offloadable() const noexcept;
    void begin_tick(plc::TimePoint now) noexcept;
    void compute() noexcept;
    void end_tick() noexcept;
    // Runs the whole ticks that fit in `seconds` (plus what earlier calls left over);
    // returns how many ran.
    std::uint64_t advance(double seconds, plc::TimePoint now) noexcept;
    // advance() without running them: the whole ticks that fit in `seconds` (plus what
    // earlier calls left over), the rest kept for the next call. A caller running them
    // in slices calls tick() that many times: the same memory as advance().
    [[nodiscard]] std::uint64_t plan_advance(double seconds) noexcept;
    // Starts the event named `name` now (its duration from now). False: no such event.
    bool trigger(std::string_view name, plc::TimePoint now) noexcept;

    // Where a tick starts reading: the scenario's own record, the CPU Unit's words it
    // copies in, its image, tags and programs (null: unused slot). Stable from compile on;
    // a caller ticking many scenarios in a row prefetches the next one's while one ticks
    // (at 1,000 CPU Units each is cold by its next tick).
    static constexpr std::size_t prefetch_count = 10;
    [[nodiscard]] std::array<const void*, prefetch_count> prefetch_addresses() const noexcept;

    [[nodiscard]] double time() const noexcept;
    [[nodiscard]] std::uint64_t ticks() const noexcept;
    [[nodiscard]] const TransportFaults& transport() const noexcept;
    [[nodiscard]] Status status() const;

    struct Impl;

  private:
    explicit Scenario(std::unique_ptr<Impl> impl);
    std::unique_ptr<Impl> impl_;
};

}  // namespace fins::scenario
