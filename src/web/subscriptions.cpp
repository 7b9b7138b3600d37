// WebSocket subscriptions (contract in subscriptions.hpp).
#include "web/subscriptions.hpp"

#include <algorithm>
#include <random>

#include <fmt/core.h>

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

Subscriptions::Subscriptions(WebContext& context, std::string session)
    : context_(context), session_(std::move(session)) {}

std::string Subscriptions::hello() const {
    return dump(Json{{"type", "hello"}, {"session", session_}, {"seq", seq_}});
}

std::string Subscriptions::stamp(Json message) {
    message["seq"] = ++seq_;
    std::string text = dump(message);
    history_.emplace_back(seq_, text);
    history_size_ += text.size();
    while (history_size_ > history_bytes && !history_.empty()) {
        history_size_ -= history_.front().second.size();
        history_.pop_front();
    }
    return text;
}

void Subscriptions::error(std::string_view id, std::string_view message,
                          std::vector<std::string>& out) {
    out.push_back(stamp(Json{{"id", id}, {"type", "error"}, {"error", message}}));
}

std::optional<ResumeRequest> Subscriptions::on_message(std::string_view text,
                                                       std::vector<std::string>& out) {
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

void Subscriptions::subscribe(const Json& j, std::vector<std::string>& out) {
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
    sub.target = target;
    if (const auto topic = j.find("topic"); topic != j.end()) {
        const std::string t = topic->is_string() ? topic->get<std::string>() : "";
        if (t != "status" && t != "errors" && t != "events")
            return error(id, "\"topic\" must be status, errors or events", out);
        sub.topic = t;
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
        sub.query = std::move(*query);
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
                         std::vector<std::string>& out) {
    for (auto& s : subs_) {
        if (now < s.next_due) continue;
        if (s.topic.empty())
            poll_data(s, now, wall, out);
        else
            poll_topic(s, now, out);
    }
}

void Subscriptions::poll_data(Sub& s, SteadyTime now, std::chrono::system_clock::time_point wall,
                              std::vector<std::string>& out) {
    const auto& memory = s.target->plc->memory();
    if (auto r = read_raw(memory, s.query, wall, scratch_); !r) {
        // The range became invalid (the current EM bank changed): say so once.
        if (r.error().message != s.last_error) {
            s.last_error = r.error().message;
            error(s.id, s.last_error, out);
            s.next_due = now + context_.options.min_interval;
        }
        return;
    }
    if (!s.snapshot && scratch_ == s.raw) return;  // the common case: nothing changed
    s.raw.swap(scratch_);
    auto values = decode_values(s.query, s.raw);
    if (!values) {
        if (values.error().message != s.last_error) {
            s.last_error = values.error().message;
            error(s.id, s.last_error, out);
            s.next_due = now + context_.options.min_interval;
        }
        s.snapshot = true;  // the last values sent are stale now
        return;
    }
    s.last_error.clear();
    if (s.snapshot || !s.last.is_array() || s.last.size() != values->size()) {
        out.push_back(stamp(Json{{"id", s.id}, {"type", "snapshot"}, {"values", *values}}));
    } else {
        Json changes = Json::array();
        for (std::size_t i = 0; i < values->size(); ++i)
            if ((*values)[i] != s.last[i]) changes.push_back(Json::array({i, (*values)[i]}));
        if (changes.empty()) {  // only a forced flag moved: nothing the client shows
            s.last = std::move(*values);
            return;
        }
        out.push_back(stamp(Json{{"id", s.id}, {"type", "delta"}, {"changes", changes}}));
    }
    s.last = std::move(*values);
    s.snapshot = false;
    s.next_due = now + context_.options.min_interval;
}

void Subscriptions::poll_topic(Sub& s, SteadyTime now, std::vector<std::string>& out) {
    Json value = s.topic == "status"   ? status_object(context_, *s.target)
                 : s.topic == "errors" ? errors_object(*s.target)
                                       : events_object(*s.target);
    if (!s.snapshot && value == s.last) return;
    out.push_back(stamp(Json{{"id", s.id}, {"type", "snapshot"}, {"value", value}}));
    s.last = std::move(value);
    s.snapshot = false;
    s.next_due = now + context_.options.min_interval;
}

void Subscriptions::resync() noexcept {
    for (auto& s : subs_) {
        s.snapshot = true;
        s.next_due = {};
    }
}

bool Subscriptions::replay_after(std::uint64_t seq, std::vector<std::string>& out) {
    if (seq >= seq_) return true;  // nothing missed
    if (history_.empty() || history_.front().first > seq + 1) {
        resync();
        return false;
    }
    for (const auto& [n, text] : history_)
        if (n > seq) out.push_back(text);
    return true;
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

std::string new_session_id() {
    static thread_local std::mt19937_64 generator{std::random_device{}()};
    return fmt::format("{:016x}{:016x}", generator(), generator());
}

}  // namespace fins::web
