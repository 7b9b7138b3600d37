// PlcPoller's writes: 01 02 MEMORY AREA WRITE of a checked value, then 01 01 of the same
// words to read it back; at most max_pending_writes per PLC, none while it is offline.
// Writes to the same words run one at a time, in the order they came: a write's read back
// is taken before the next write to those words is sent, so it is that write's value.
#include <algorithm>

#include <fmt/format.h>

#include "bridge/poll/poller_parts.hpp"
#include "bridge/poll/tag_decode.hpp"
#include "fins/commands/memory_area.hpp"
#include "fins/values.hpp"

namespace fins::bridge {

namespace {

// Whether two tags share a word (a write to one changes what the other reads back).
bool overlaps(const Tag& a, const Tag& b) {
    if (a.read_start.area_code != b.read_start.area_code) return false;
    const std::size_t a0 = a.read_start.word;
    const std::size_t b0 = b.read_start.word;
    return a0 < b0 + b.words && b0 < a0 + a.words;
}

}  // namespace

std::optional<std::string> PlcPoller::write(const Tag& tag, const Encoded& value, std::string id) {
    if (!running_) return "this instance does not poll the PLC";
    // A UDP PLC being contacted for the first time takes frames already (as its polls do).
    const bool can_send = state_ == State::online ||
                          (state_ == State::connecting && plc_.transport == Transport::udp);
    if (!can_send)
        return last_error_.empty() ? std::string("PLC offline") : "PLC offline: " + last_error_;
    if (writes_.size() >= max_pending_writes)
        return fmt::format("{} writes already wait for this PLC", max_pending_writes);
    auto op = std::make_unique<PendingWrite>();
    op->id = std::move(id);
    op->tag = &tag;
    std::vector<std::uint8_t> data;
    MemoryAddress start = tag.read_start;
    std::uint16_t count = static_cast<std::uint16_t>(tag.words);
    if (tag.type == TagType::bits) {
        start = *to_memory_address(tag.address, Access::bit);
        count = 1;
        data.push_back(value.bit ? 1 : 0);
    } else if (tag.type == TagType::string) {
        auto words = string_to_words(value.text, tag.words);
        if (!words) return describe(words.error());
        data = words_to_bytes(*words);
    } else {
        data = words_to_bytes({value.words.data(), value.count});
    }
    op->parameters.resize(max_parameter_size);
    ByteWriter w(op->parameters);
    MemoryAreaWrite{start, count, data}.encode(w);
    op->parameters.resize(w.written().size());
    op->waiting = std::any_of(writes_.begin(), writes_.end(),
                              [&tag](const auto& other) { return overlaps(*other->tag, tag); });
    PendingWrite& queued = *op;
    writes_.push_back(std::move(op));
    if (!queued.waiting) send_write(queued);
    return std::nullopt;
}

void PlcPoller::send_write(PendingWrite& op) {
    op.waiting = false;
    Request r{Request::Kind::write};
    r.op = &op;
    r.command = MemoryAreaWrite::code;
    enqueue(r);
}

void PlcPoller::write_answered(Request& r, const ResponseView* response, std::error_code failure) {
    if (r.kind == Request::Kind::read_back || failure) {
        finish_write(*r.op, failure, response);
        return;
    }
    // Written: read the same words back, before any frame still waiting.
    r.op->end_code = response->code.raw();
    std::array<std::uint8_t, 6> p{};
    ByteWriter w(p);
    MemoryAreaRead{r.op->tag->read_start, static_cast<std::uint16_t>(r.op->tag->words)}.encode(w);
    r.op->parameters.assign(p.begin(), p.end());
    Request back{Request::Kind::read_back};
    back.op = r.op;
    back.command = MemoryAreaRead::code;
    ready_.push_front(back);
}

void PlcPoller::finish_write(PendingWrite& op, std::error_code error,
                             const ResponseView* response) {
    WriteResponse r;
    r.id = op.id;
    if (error) {
        r.ok = false;
        r.error = error_text(error);
        if (is_end_code(error))
            r.end_code = static_cast<std::uint16_t>(error.value());
        else if (op.end_code != 0 || response != nullptr)
            r.end_code = op.end_code;
    } else {
        r.end_code = op.end_code;
        if (response->data.size() != 2 * op.tag->words) {
            r.ok = false;
            r.error = "the read back did not fit the tag: " +
                      describe(make_error_code(ClientError::malformed_response));
        } else {
            TagSample s;
            decode_words(*op.tag, response->data, 0, s);
            r.ok = true;
            r.value = to_json(op.tag->type, s.value);
        }
    }
    auto it = std::find_if(writes_.begin(), writes_.end(),
                           [&op](const auto& p) { return p.get() == &op; });
    std::unique_ptr<PendingWrite> keep;
    if (it != writes_.end()) {
        keep = std::move(*it);
        writes_.erase(it);
    }
    events_.write_done(plc_, r);
    // The writes that waited for this one and now have no earlier write to their words:
    // sent now, or failed as this one did when the PLC is gone.
    const bool can_send = state_ == State::online ||
                          (state_ == State::connecting && plc_.transport == Transport::udp);
    for (std::size_t i = 0; i < writes_.size(); ++i) {
        PendingWrite& w = *writes_[i];
        if (!w.waiting || !overlaps(*w.tag, *op.tag)) continue;
        const bool behind =
            std::any_of(writes_.begin(), writes_.begin() + static_cast<std::ptrdiff_t>(i),
                        [&w](const auto& e) { return overlaps(*e->tag, *w.tag); });
        if (behind) continue;
        if (can_send) {
            send_write(w);
        } else {
            finish_write(w, error ? error : make_error_code(ClientError::timeout), nullptr);
            return;  // that call went on with the rest
        }
    }
}

}  // namespace fins::bridge
