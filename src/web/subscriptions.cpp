// WebSocket subscriptions (contract in subscriptions.hpp).
#include "web/subscriptions.hpp"

#ifdef _WIN32
#include <windows.h>

#include <bcrypt.h>  // after windows.h, which it needs
#else
#include <sys/random.h>
#endif

#include <algorithm>
#include <array>
#include <cerrno>
#include <iterator>
#include <limits>
#include <system_error>

#include <fmt/format.h>

#include "plc/plc.hpp"
#include "server/control/control_dispatch.hpp"
#include "web/api.hpp"

namespace fins::web {

namespace {

using Json = nlohmann::json;

constexpr std::size_t max_id_size = 64;

std::string dump(const Json& j) {
    return j.dump(-1, ' ', false, Json::error_handler_t::replace);
}

}  // namespace

std::string Message::text() const {
    if (!body) return head;
    std::string t;
    t.reserve(size());
    t += head;
    t += *body;
    t += '}';
    return t;
}

Subscriptions::Subscriptions(WebContext& context, std::string session)
    : context_(context), session_(std::move(session)) {}

std::string Subscriptions::hello() const {
    return dump(Json{{"type", "hello"}, {"session", session_}, {"seq", seq_}});
}

// `message.head` begins after the seq: {"seq":N, is put in front here.
Message& Subscriptions::stamp(Message message, std::vector<Message>& out) {
    message.head.insert(0, fmt::format(R"({{"seq":{},)", ++seq_));
    history_size_ += message.size();
    history_.emplace_back(seq_, message);
    while (history_size_ > history_bytes && !history_.empty()) {
        history_size_ -= history_.front().second.size();
        history_.pop_front();
    }
    out.push_back(std::move(message));
    return out.back();
}

void Subscriptions::error(std::string_view id, std::string_view message,
                          std::vector<Message>& out) {
    const std::string text = dump(Json{{"id", id}, {"type", "error"}, {"error", message}});
    stamp(Message{text.substr(1), nullptr}, out);  // without its "{"
}

std::optional<ResumeRequest> Subscriptions::on_message(std::string_view text,
                                                       std::vector<Message>& out) {
    const Json j = Json::parse(text, nullptr, false);
    if (j.is_discarded() || !j.is_object()) {
        error("", "a message must be a JSON object", out);
        return std::nullopt;
    }
    const auto op = j.find("op");
    const std::string name = op != j.end() && op->is_string() ? op->get<std::string>() : "";
    if (name == "subscribe") {
        subscribe(j, out);
    } else if (name == "unsubscribe") {
        const auto id = j.find("id");
        if (id == j.end() || !id->is_string()) {
            error("", "unsubscribe needs \"id\"", out);
            return std::nullopt;
        }
        const auto before = subs_.size();
        std::erase_if(subs_,
                      [&](const Sub& s) { return s.id == id->get_ref<const std::string&>(); });
        if (subs_.size() == before) error(id->get<std::string>(), "no such subscription", out);
    } else if (name == "resume") {
        const auto session = j.find("session");
        const auto seq = j.find("seq");
        if (session == j.end() || !session->is_string() || seq == j.end() ||
            !seq->is_number_unsigned()) {
            error("", "resume needs \"session\" (a string) and \"seq\" (a number)", out);
            return std::nullopt;
        }
        return ResumeRequest{session->get<std::string>(), seq->get<std::uint64_t>()};
    } else {
        error("", "\"op\" must be subscribe, unsubscribe or resume", out);
    }
    return std::nullopt;
}

void Subscriptions::subscribe(const Json& j, std::vector<Message>& out) {
    const auto id_it = j.find("id");
    if (id_it == j.end() || !id_it->is_string() || id_it->get_ref<const std::string&>().empty() ||
        id_it->get_ref<const std::string&>().size() > max_id_size)
        return error(
            "", fmt::format("subscribe needs \"id\": a string of 1 to {} characters", max_id_size),
            out);
    const std::string id = id_it->get<std::string>();
    std::optional<std::string_view> wanted;
    if (const auto it = j.find("plc"); it != j.end() && !it->is_null()) {
        if (!it->is_string()) return error(id, "\"plc\" must be a string", out);
        wanted = it->get_ref<const std::string&>();
    }
    std::string why;
    const auto* target = server::find_control_target(context_.targets, wanted, why);
    if (target == nullptr) return error(id, why, out);
    Sub sub;
    sub.id = id;
    sub.id_json = dump(*id_it);
    if (const auto topic = j.find("topic"); topic != j.end()) {
        const std::string t = topic->is_string() ? topic->get<std::string>() : "";
        if (t != "status" && t != "errors" && t != "events")
            return error(id, "\"topic\" must be status, errors or events", out);
        sub.watch = context_.watches->topic(*target, t);
    } else {
        const auto address = j.find("address");
        if (address == j.end() || !address->is_string())
            return error(id, "subscribe needs \"address\" or \"topic\"", out);
        std::size_t count = 1;
        if (const auto c = j.find("count"); c != j.end()) {
            if (!c->is_number_unsigned()) return error(id, "\"count\" must be a number", out);
            count = c->get<std::size_t>();
        }
        std::string as = "uint16";
        if (const auto a = j.find("as"); a != j.end()) {
            if (!a->is_string()) return error(id, "\"as\" must be a string", out);
            as = a->get<std::string>();
        }
        auto query = make_query(target->plc->memory(), address->get<std::string>(), count, as);
        if (!query) return error(id, query.error().message, out);
        sub.watch = context_.watches->values(*target, *query);
    }
    // The same id again replaces that subscription (a page changing its window).
    const auto same =
        std::find_if(subs_.begin(), subs_.end(), [&](const Sub& s) { return s.id == id; });
    if (same != subs_.end()) {
        *same = std::move(sub);
        return;
    }
    if (subs_.size() >= context_.options.max_subscriptions)
        return error(id,
                     fmt::format("at most {} subscriptions a connection",
                                 context_.options.max_subscriptions),
                     out);
    subs_.push_back(std::move(sub));
}

void Subscriptions::poll(SteadyTime now, std::chrono::system_clock::time_point wall,
                         std::vector<Message>& out) {
    std::size_t unlimited = std::numeric_limits<std::size_t>::max();
    poll(now, wall, out, unlimited);
}

void Subscriptions::poll(SteadyTime now, std::chrono::system_clock::time_point wall,
                         std::vector<Message>& out, std::size_t& budget) {
    const std::size_t n = subs_.size();
    for (std::size_t k = 0; k < n; ++k) {
        Sub& s = subs_[(next_ + k) % n];
        const std::size_t cost = s.watch->due(now) ? s.watch->cost() : 0;
        if (cost > 0 && budget == 0) {
            next_ = (next_ + k) % n;  // this one first next time
            return;
        }
        budget -= std::min(budget, cost);
        poll_one(s, now, wall, out);
    }
}

void Subscriptions::poll_one(Sub& s, SteadyTime now, std::chrono::system_clock::time_point wall,
                             std::vector<Message>& out) {
    Watch& w = *s.watch;
    // Once per interval for every subscriber; a subscription sends when its watch moved
    // on, so at most once per interval too (plus its first snapshot).
    w.refresh(context_, now, wall);
    if (!w.error().empty()) {
        // Say so once; the values last sent are stale now.
        if (w.error() != s.last_error) {
            s.last_error = w.error();
            error(s.id, s.last_error, out);
        }
        s.snapshot = true;
        return;
    }
    s.last_error.clear();
    if (!s.snapshot && s.generation == w.generation()) return;  // nothing changed
    if (!s.snapshot && s.generation + 1 == w.generation() && w.delta() != nullptr) {
        stamp(Message{fmt::format(R"("id":{},"type":"delta","changes":)", s.id_json), w.delta()},
              out);
    } else {
        const auto& snapshot = w.snapshot();
        if (snapshot == nullptr) return;  // nothing read yet
        stamp(Message{fmt::format(R"("id":{},"type":"snapshot","{}":)", s.id_json,
                                  w.topic() ? "value" : "values"),
                      snapshot},
              out);
    }
    s.generation = w.generation();
    s.snapshot = false;
}

void Subscriptions::resync() noexcept {
    for (auto& s : subs_)
        s.snapshot = true;
}

bool Subscriptions::replay_after(std::uint64_t seq, std::vector<Message>& out) {
    if (seq >= seq_) return true;  // nothing missed
    if (history_.empty() || history_.front().first > seq + 1) {
        resync();
        return false;
    }
    for (const auto& [n, message] : history_)
        if (n > seq) out.push_back(message);
    return true;
}

namespace {

void append_texts(const std::vector<Message>& messages, std::vector<std::string>& out) {
    for (const auto& m : messages)
        out.push_back(m.text());
}

}  // namespace

std::optional<ResumeRequest> Subscriptions::on_message(std::string_view text,
                                                       std::vector<std::string>& out) {
    std::vector<Message> messages;
    auto r = on_message(text, messages);
    append_texts(messages, out);
    return r;
}

void Subscriptions::poll(SteadyTime now, std::chrono::system_clock::time_point wall,
                         std::vector<std::string>& out) {
    std::vector<Message> messages;
    poll(now, wall, messages);
    append_texts(messages, out);
}

bool Subscriptions::replay_after(std::uint64_t seq, std::vector<std::string>& out) {
    std::vector<Message> messages;
    const bool complete = replay_after(seq, messages);
    append_texts(messages, out);
    return complete;
}

void ResumeStore::expire(SteadyTime now) {
    while (!kept_.empty() && (kept_.front().first + options_.resume_window <= now ||
                              kept_.size() > options_.max_resumable))
        kept_.pop_front();
}

void ResumeStore::keep(std::unique_ptr<Subscriptions> subs, SteadyTime now) {
    if (subs == nullptr || options_.max_resumable == 0) return;
    kept_.emplace_back(now, std::move(subs));
    expire(now);
}

std::unique_ptr<Subscriptions> ResumeStore::take(std::string_view session, SteadyTime now) {
    expire(now);
    for (auto it = kept_.begin(); it != kept_.end(); ++it)
        if (it->second->session() == session) {
            auto subs = std::move(it->second);
            kept_.erase(it);
            return subs;
        }
    return nullptr;
}

// 128 bits from the kernel's CSPRNG (getrandom(2); BCryptGenRandom on Windows): a session
// name is a capability (it takes over another page's subscriptions), so it must not be
// guessable from others.
std::string new_session_id() {
    std::array<unsigned char, 16> bits{};
#ifdef _WIN32
    // Windows' CSPRNG (the system-preferred RNG).
    if (::BCryptGenRandom(nullptr, bits.data(), static_cast<ULONG>(bits.size()),
                          BCRYPT_USE_SYSTEM_PREFERRED_RNG) != 0)
        throw std::system_error(EIO, std::generic_category(), "BCryptGenRandom");
#else
    std::size_t got = 0;
    while (got < bits.size()) {
        const auto n = ::getrandom(bits.data() + got, bits.size() - got, 0);
        if (n < 0 && errno == EINTR) continue;
        if (n < 0) throw std::system_error(errno, std::generic_category(), "getrandom");
        got += static_cast<std::size_t>(n);
    }
#endif
    std::string hex;
    hex.reserve(2 * bits.size());
    for (const auto b : bits)
        fmt::format_to(std::back_inserter(hex), "{:02x}", b);
    return hex;
}

}  // namespace fins::web
