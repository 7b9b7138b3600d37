// What the WebSocket subscriptions of every connection watch, computed once and shared
// (issue 16's cost bound: 50 pages watching the same 1,000 changing words must not cost
// 50 times one page). A Watch is one distinct (CPU Unit, range, format) or (CPU Unit,
// topic); every subscription naming it holds it, and the registry forgets it with the last.
//
// A Watch refreshes at most once per interval, whichever subscription asks first:
//   1. read the raw bytes; memcmp with the last read: equal, nothing more to do;
//   2. print the values as JSON tokens with fmt into a reused buffer (typed views the
//      fast path does not cover go through decode_values once);
//   3. compare token by token with the last values; none changed (a forced flag moved):
//      nothing; else the generation rises and the delta's text ([[offset,value],...]) is
//      written once into a new immutable buffer that every subscriber's message shares.
// The snapshot's text ([values...]) is written at most once per generation, when a
// subscriber needs one. A topic (status, errors, events) is its object's text, built at
// most every topic_interval (an idle page's cost is building it), and at the next tick
// after a write or control request through the API (touch_topics()); a new text is a
// new generation. Pure: no sockets, time passed in.
#pragma once

#include <chrono>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <string_view>
#include <unordered_map>
#include <vector>

#include "web/memory_values.hpp"

namespace fins::server {
struct ControlTarget;
}

namespace fins::web {

struct WebContext;
using SteadyTime = std::chrono::steady_clock::time_point;
using SharedText = std::shared_ptr<const std::string>;

// A topic's object (status, errors, events) against the tick's budget, in words.
inline constexpr std::size_t topic_cost = 256;

// How often a topic's object is built again to see whether it changed.
inline constexpr std::chrono::milliseconds topic_interval{500};

class Watch {
  public:
    Watch(const server::ControlTarget& target, ValueQuery query);
    Watch(const server::ControlTarget& target, std::string topic);

    // Reads again when `now` reached the next refresh (else keeps the last result).
    void refresh(const WebContext& context, SteadyTime now,
                 std::chrono::system_clock::time_point wall);

    // True when refresh() at `now` reads (the interval passed, or never read).
    [[nodiscard]] bool due(SteadyTime now) const noexcept {
        return !read_once_ || now >= next_refresh_;
    }
    // What a refresh costs, in the unit of the tick's budget (WebOptions::
    // max_ws_words_per_tick): the elements read, or topic_cost for a topic's object.
    [[nodiscard]] std::size_t cost() const noexcept;
    // Rises with every change of what a client shows (values, object, error state).
    [[nodiscard]] std::uint64_t generation() const noexcept { return generation_; }
    // The next refresh reads whatever the time (something changed it).
    void touch() noexcept { next_refresh_ = {}; }
    // Non-empty: the range cannot be read or decoded now (the client is told once).
    [[nodiscard]] const std::string& error() const noexcept { return error_; }
    [[nodiscard]] bool topic() const noexcept { return !topic_.empty(); }
    // "[v0,v1,...]" (a range) or the object's JSON text (a topic), for this generation.
    [[nodiscard]] const SharedText& snapshot();
    // "[[offset,value],...]" from generation()-1 to generation(); null when that step
    // was no delta (the first read, an error in between, a topic).
    [[nodiscard]] const SharedText& delta() const noexcept { return delta_; }

  private:
    void refresh_values(std::chrono::system_clock::time_point wall);
    void refresh_topic(const WebContext& context, std::chrono::system_clock::time_point wall);
    bool print_tokens();  // raw_ -> next_text_/next_ends_; false with error_ set
    void set_error(std::string message);

    const server::ControlTarget* target_;
    std::string topic_;
    ValueQuery query_;
    std::uint64_t generation_ = 0;
    bool read_once_ = false;
    SteadyTime next_refresh_{};
    std::string error_;
    std::vector<std::uint8_t> raw_, scratch_;
    // The values as JSON tokens: text_[ends_[i-1], ends_[i]) is value i.
    std::string text_, next_text_;
    std::vector<std::uint32_t> ends_, next_ends_;
    bool have_values_ = false;
    SharedText snapshot_, delta_;
};

// The watches of one server (every connection's subscriptions), keyed by what they watch.
class Watches {
  public:
    std::shared_ptr<Watch> values(const server::ControlTarget& target, const ValueQuery& query);
    std::shared_ptr<Watch> topic(const server::ControlTarget& target, std::string_view topic);
    // Every topic is built again at its next refresh (the API changed the PLC).
    void touch_topics();
    // Distinct watches alive now (tests).
    [[nodiscard]] std::size_t size();

  private:
    std::shared_ptr<Watch> find_or_make(std::string key, const std::function<Watch()>& make);
    std::unordered_map<std::string, std::weak_ptr<Watch>> watches_;
};

}  // namespace fins::web
