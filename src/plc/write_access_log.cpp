#include "plc/write_access_log.hpp"

#include <algorithm>

#include "plc/clock.hpp"

namespace fins::plc {

WriteAccessLog::WriteAccessLog(const Profile&, Storage& storage)
    : state_(storage.object<State>("write_access_log", Retention::retained)) {
    // A damaged state file must not index past the records.
    if (state_.count > log_max_records) state_.count = log_max_records;
}

void WriteAccessLog::record(const NodeAddress& source, CommandCode command, EndCode,
                            std::chrono::system_clock::time_point now) noexcept {
    const std::int64_t second =
        std::chrono::floor<std::chrono::seconds>(now).time_since_epoch().count();
    const std::uint64_t clock_version = clock_ != nullptr ? clock_->version() : 0;
    if (last_.valid && last_.second == second && last_.clock_version == clock_version &&
        last_.source == source && last_.command == command)
        return;
    last_ = {source, command, second, clock_version, true};
    const LogTime time = clock_ != nullptr ? to_log_time(clock_->read(now)) : to_log_time(now);
    const WriteAccessRecord entry{source, 0x00, command, time};
    // The newest record is already this one (the same writer, command and second: a
    // scenario writing every tick, a client polling writes): writing it again would change
    // nothing a reader sees, neither the records nor which is oldest.
    if (newest_ < state_.count && state_.slots[newest_].sequence == state_.sequence &&
        state_.slots[newest_].record == entry)
        return;
    const std::uint32_t sequence = ++state_.sequence;
    auto* const begin = state_.slots.begin();
    auto* const end = begin + state_.count;
    auto* same = std::find_if(begin, end, [&source](const Slot& s) {
        return s.record.source.network == source.network && s.record.source.node == source.node;
    });
    if (same != end) {
        *same = Slot{entry, sequence};
        newest_ = static_cast<std::size_t>(same - begin);
        return;
    }
    if (state_.count == log_max_records) {
        auto* oldest = std::min_element(
            begin, end, [](const Slot& a, const Slot& b) { return a.sequence < b.sequence; });
        std::copy(oldest + 1, end, oldest);
        --state_.count;
    }
    newest_ = state_.count;
    state_.slots[state_.count++] = Slot{entry, sequence};
}

}  // namespace fins::plc
