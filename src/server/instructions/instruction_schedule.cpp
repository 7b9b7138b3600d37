// InstructionSchedule: [[schedule]] entries run at their period (instruction_schedule.hpp).
#include "server/instructions/instruction_schedule.hpp"

#include <spdlog/spdlog.h>

namespace fins::server {

struct InstructionSchedule::Entry {
    Entry(const asio::any_io_executor& ex, ScheduledInstruction s)
        : timer(ex), scheduled(std::move(s)) {}
    asio::steady_timer timer;
    ScheduledInstruction scheduled;
    std::chrono::steady_clock::time_point next{};
    bool running = false;
    EntryCounters counters;
};

InstructionSchedule::InstructionSchedule(asio::any_io_executor executor,
                                         NetworkInstructions& engine,
                                         std::vector<ScheduledInstruction> entries)
    : executor_(std::move(executor)), engine_(engine) {
    for (auto& e : entries)
        entries_.push_back(std::make_unique<Entry>(executor_, std::move(e)));
}

InstructionSchedule::~InstructionSchedule() {
    stop();
}

void InstructionSchedule::start() {
    const auto now = std::chrono::steady_clock::now();
    for (std::size_t i = 0; i < entries_.size(); ++i) {
        entries_[i]->next = now + entries_[i]->scheduled.every;
        arm(i);
    }
}

void InstructionSchedule::stop() {
    *alive_ = false;
    alive_ = std::make_shared<bool>(true);
    for (auto& e : entries_)
        e->timer.cancel();
}

const InstructionSchedule::EntryCounters& InstructionSchedule::counters(std::size_t entry) const {
    return entries_.at(entry)->counters;
}

void InstructionSchedule::arm(std::size_t index) {
    Entry& e = *entries_[index];
    e.timer.expires_at(e.next);
    e.timer.async_wait(
        [this, index, alive = std::weak_ptr<bool>(alive_)](boost::system::error_code ec) {
            const auto a = alive.lock();
            if (ec || !a || !*a) return;
            tick(index);
        });
}

void InstructionSchedule::tick(std::size_t index) {
    Entry& e = *entries_[index];
    // Fixed rate without catching up: a late tick moves the next one past now.
    const auto now = std::chrono::steady_clock::now();
    e.next += e.scheduled.every;
    if (e.next <= now) e.next = now + e.scheduled.every;
    arm(index);
    if (e.running) {
        ++e.counters.skipped;
        return;
    }
    e.running = true;
    ++e.counters.runs;
    engine_.start(e.scheduled.request, [this, index, alive = std::weak_ptr<bool>(alive_)](
                                           const InstructionResult& r) {
        const auto a = alive.lock();
        if (!a || !*a) return;
        Entry& entry = *entries_[index];
        entry.running = false;
        auto& c = entry.counters;
        const bool changed = r.error_id != c.last_error_id || r.error_id_ex != c.last_error_id_ex;
        ++(r.done() ? c.done : c.errors);
        if (changed && !r.done())
            spdlog::warn("finsd: schedule {} ({}): ErrorID {:04X} ErrorIDEx {:04X}: {}", index,
                         instruction_kind_name(entry.scheduled.request.kind), r.error_id,
                         r.error_id_ex, r.detail);
        else if (changed)
            spdlog::info("finsd: schedule {} ({}): done again", index,
                         instruction_kind_name(entry.scheduled.request.kind));
        c.last_error_id = r.error_id;
        c.last_error_id_ex = r.error_id_ex;
    });
}

}  // namespace fins::server
