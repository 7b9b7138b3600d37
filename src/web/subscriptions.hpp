// One WebSocket client's subscriptions, as a pure state machine: client messages in,
// server messages out, time passed in (no sockets, no clock of its own), so the tests
// and fuzz/fuzz_http.cpp drive deltas, coalescing, seq and resume without waiting.
//
// Protocol (docs/web.md "WebSocket", docs/api/openapi.yaml /ws):
//   in   {"op":"subscribe","id":"s1","plc":"press1","address":"D0","count":200,"as":"uint16"}
//        {"op":"subscribe","id":"st","topic":"status"|"errors"|"events"}
//        {"op":"unsubscribe","id":"s1"}
//        {"op":"resume","session":"...","seq":N}      (the caller handles it: ResumeStore)
//   out  {"seq":N,"id":"s1","type":"snapshot","values":[...]}
//        {"seq":N,"id":"s1","type":"delta","changes":[[offset,value],...]}
//        {"seq":N,"id":"st","type":"snapshot","value":{...}}
//        {"seq":N,"id":"s1","type":"error","error":"..."}
// A subscription's first message (its snapshot) goes out at the first poll, which the
// session runs at once after the subscribe; then it sends when what it watches changed,
// at most once per min_interval (changes in between are coalesced into one delta against
// the last message sent). What a subscription watches is a shared Watch (watches.hpp):
// read, compared and printed once per interval for every connection watching it, and a
// message's values are that Watch's immutable text, shared, not copied (Message). seq
// rises by one per message. The last history_bytes of messages are kept, so a client
// that reconnects with "resume" gets what it missed, or fresh snapshots if that is gone.
#pragma once

#include <chrono>
#include <cstdint>
#include <deque>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <unordered_map>
#include <vector>

#include <nlohmann/json.hpp>

#include "web/memory_values.hpp"
#include "web/watches.hpp"
#include "web/web_context.hpp"

namespace fins::web {

// One message to a client: `head`, then, when `body` is set, the shared text and "}"
// (the values of a snapshot or delta, written once for every subscriber).
struct Message {
    std::string head;
    SharedText body;
    [[nodiscard]] std::size_t size() const noexcept {
        return head.size() + (body ? body->size() + 1 : 0);
    }
    [[nodiscard]] std::string text() const;
};

// Bytes of sent messages each client keeps for "resume".
inline constexpr std::size_t history_bytes = 256 * 1024;

struct ResumeRequest {
    std::string session;
    std::uint64_t seq = 0;
};

class Subscriptions {
  public:
    Subscriptions(WebContext& context, std::string session);

    [[nodiscard]] const std::string& session() const noexcept { return session_; }
    [[nodiscard]] std::uint64_t seq() const noexcept { return seq_; }
    [[nodiscard]] std::size_t size() const noexcept { return subs_.size(); }
    // {"type":"hello","session":...,"seq":N}
    [[nodiscard]] std::string hello() const;

    // A client message: answers (errors) go to `out`; a "resume" is returned for the caller.
    std::optional<ResumeRequest> on_message(std::string_view text, std::vector<Message>& out);
    // The messages due at `now` (`wall` stamps clock pulses and the like).
    void poll(SteadyTime now, std::chrono::system_clock::time_point wall,
              std::vector<Message>& out);
    // The same within `budget` (Watch::cost() of the watches refreshed, taken from it):
    // subscriptions are polled round-robin from where the last poll stopped; when the
    // budget is spent, the rest wait for the next poll (their watch is not read, nothing
    // is lost: their next message carries what changed meanwhile). A poll with some
    // budget left always refreshes at least one due watch, however large.
    void poll(SteadyTime now, std::chrono::system_clock::time_point wall, std::vector<Message>& out,
              std::size_t& budget);
    // Every subscription's next message is a snapshot (the client fell behind, or what
    // it missed is no longer in the history).
    void resync() noexcept;
    // The messages after `seq` still in the history to `out`; false (and a resync) when
    // some are gone.
    bool replay_after(std::uint64_t seq, std::vector<Message>& out);

    // The same with whole texts (tests and the fuzzer read them).
    std::optional<ResumeRequest> on_message(std::string_view text, std::vector<std::string>& out);
    void poll(SteadyTime now, std::chrono::system_clock::time_point wall,
              std::vector<std::string>& out);
    bool replay_after(std::uint64_t seq, std::vector<std::string>& out);

  private:
    struct Sub {
        std::string id;
        std::string id_json;  // the id as a JSON string, for the message heads
        std::shared_ptr<Watch> watch;
        std::uint64_t generation = 0;  // of the watch, last sent
        std::string last_error;
        bool snapshot = true;
    };

    Message& stamp(Message message, std::vector<Message>& out);
    void error(std::string_view id, std::string_view message, std::vector<Message>& out);
    void subscribe(const nlohmann::json& j, std::vector<Message>& out);
    void poll_one(Sub& s, SteadyTime now, std::chrono::system_clock::time_point wall,
                  std::vector<Message>& out);

    WebContext& context_;
    std::string session_;
    std::uint64_t seq_ = 0;
    std::vector<Sub> subs_;
    std::size_t next_ = 0;  // where the next budgeted poll starts
    std::deque<std::pair<std::uint64_t, Message>> history_;
    std::size_t history_size_ = 0;
};

// Subscriptions of closed connections, kept for resume_window so that a page that
// reconnects picks up where it was; at most max_resumable (the oldest goes first).
class ResumeStore {
  public:
    explicit ResumeStore(const WebOptions& options) : options_(options) {}
    void keep(std::unique_ptr<Subscriptions> subs, SteadyTime now);
    // The subscriptions of `session` (nullptr: unknown or expired); removed from the store.
    std::unique_ptr<Subscriptions> take(std::string_view session, SteadyTime now);
    [[nodiscard]] std::size_t size() const noexcept { return kept_.size(); }

  private:
    void expire(SteadyTime now);
    const WebOptions& options_;
    std::deque<std::pair<SteadyTime, std::unique_ptr<Subscriptions>>> kept_;
};

// 128 random bits as hex: a resumable session's name.
std::string new_session_id();

}  // namespace fins::web
