// Shared watches of the WebSocket subscriptions (contract in watches.hpp).
#include "web/watches.hpp"

#include <algorithm>
#include <iterator>

#include <fmt/core.h>

#include "plc/plc.hpp"
#include "server/control/control.hpp"
#include "web/api.hpp"
#include "web/web_context.hpp"

namespace fins::web {

Watch::Watch(const server::ControlTarget& target, ValueQuery query)
    : target_(&target), query_(std::move(query)) {}

Watch::Watch(const server::ControlTarget& target, std::string topic)
    : target_(&target), topic_(std::move(topic)) {}

void Watch::refresh(const WebContext& context, SteadyTime now,
                    std::chrono::system_clock::time_point wall) {
    if (read_once_ && now < next_refresh_) return;
    read_once_ = true;
    next_refresh_ = now + (topic_.empty() ? context.options.min_interval
                                          : std::max<std::chrono::milliseconds>(
                                                context.options.min_interval, topic_interval));
    if (topic_.empty())
        refresh_values(wall);
    else
        refresh_topic(context, wall);
}

std::size_t Watch::cost() const noexcept {
    return topic_.empty() ? std::max<std::size_t>(1, query_.elements) : topic_cost;
}

void Watch::set_error(std::string message) {
    if (!have_values_ && error_ == message) return;
    error_ = std::move(message);
    have_values_ = false;
    delta_.reset();
    snapshot_.reset();
    ++generation_;
}

void Watch::refresh_values(std::chrono::system_clock::time_point wall) {
    if (auto r = read_raw(target_->plc->memory(), query_, wall, scratch_); !r)
        return set_error(r.error().message);       // the range became invalid (EM bank changed)
    if (have_values_ && scratch_ == raw_) return;  // the common case: nothing changed
    raw_.swap(scratch_);
    if (!print_tokens()) return;
    if (have_values_ && next_ends_.size() == ends_.size()) {
        // Only the values that changed, as [[offset,value],...].
        std::string delta;
        auto out = std::back_inserter(delta);
        std::uint32_t old_begin = 0, new_begin = 0;
        for (std::size_t i = 0; i < ends_.size(); ++i) {
            const std::string_view before(text_.data() + old_begin, ends_[i] - old_begin);
            const std::string_view after(next_text_.data() + new_begin, next_ends_[i] - new_begin);
            if (before != after) {
                delta += delta.empty() ? "[[" : ",[";
                fmt::format_to(out, "{},", i);
                delta += after;
                delta += ']';
            }
            old_begin = ends_[i];
            new_begin = next_ends_[i];
        }
        if (delta.empty()) return;  // only a forced flag moved: nothing a client shows
        delta += ']';
        delta_ = std::make_shared<const std::string>(std::move(delta));
    } else {
        delta_.reset();
    }
    text_.swap(next_text_);
    ends_.swap(next_ends_);
    have_values_ = true;
    error_.clear();
    snapshot_.reset();
    ++generation_;
}

bool Watch::print_tokens() {
    next_text_.clear();
    next_ends_.clear();
    const auto end = [&] { next_ends_.push_back(static_cast<std::uint32_t>(next_text_.size())); };
    auto out = std::back_inserter(next_text_);
    const std::size_t elements = std::max<std::size_t>(query_.elements, 1);
    const std::size_t size = raw_.size() / elements;
    const auto f = query_.format;
    const bool plain_words =
        !query_.bits && !query_.wide &&
        (f == typed::Format::uint16 || f == typed::Format::int16 || f == typed::Format::hex);
    if (size != 0 && raw_.size() == size * elements && (query_.bits || plain_words)) {
        if (query_.bits) {
            for (std::size_t i = 0; i < elements; ++i) {
                next_text_ += (raw_[i * size + size - 1] & 1) != 0 ? '1' : '0';  // bit 1: forced
                end();
            }
            return true;
        }
        for (std::size_t i = 0; i + 1 < raw_.size(); i += 2) {
            const auto w = static_cast<std::uint16_t>(raw_[i] << 8 | raw_[i + 1]);
            if (f == typed::Format::uint16)
                fmt::format_to(out, "{}", w);
            else if (f == typed::Format::int16)
                fmt::format_to(out, "{}", static_cast<std::int16_t>(w));
            else
                fmt::format_to(out, "\"0x{:04X}\"", w);
            end();
        }
        return true;
    }
    // The other views (32/64-bit, float, BCD, ASCII, IR) through the one decoder.
    auto values = decode_values(query_, raw_);
    if (!values) {
        set_error(values.error().message);
        return false;
    }
    for (const auto& v : *values) {
        next_text_ += v.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
        end();
    }
    return true;
}

void Watch::refresh_topic(const WebContext& context, std::chrono::system_clock::time_point wall) {
    const nlohmann::json value = topic_ == "status"   ? status_object(context, *target_, wall)
                                 : topic_ == "errors" ? errors_object(*target_)
                                                      : events_object(*target_);
    next_text_.clear();
    next_text_ = value.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
    if (have_values_ && next_text_ == text_) return;
    text_.swap(next_text_);
    have_values_ = true;
    snapshot_ = std::make_shared<const std::string>(text_);
    ++generation_;
}

const SharedText& Watch::snapshot() {
    if (snapshot_ == nullptr && have_values_) {
        std::string s;
        s.reserve(text_.size() + ends_.size() + 2);
        s += '[';
        std::uint32_t begin = 0;
        for (std::size_t i = 0; i < ends_.size(); ++i) {
            if (i != 0) s += ',';
            s.append(text_, begin, ends_[i] - begin);
            begin = ends_[i];
        }
        s += ']';
        snapshot_ = std::make_shared<const std::string>(std::move(s));
    }
    return snapshot_;
}

std::shared_ptr<Watch> Watches::find_or_make(std::string key, const std::function<Watch()>& make) {
    if (const auto it = watches_.find(key); it != watches_.end())
        if (auto w = it->second.lock()) return w;
    std::erase_if(watches_, [](const auto& kv) { return kv.second.expired(); });
    auto w = std::make_shared<Watch>(make());
    watches_[std::move(key)] = w;
    return w;
}

std::shared_ptr<Watch> Watches::values(const server::ControlTarget& target,
                                       const ValueQuery& query) {
    const auto& m = query.memory;
    auto key =
        fmt::format("{}|{:02X}{:04X}{:02X}|{}|{}|{}|{}|{}", static_cast<const void*>(&target),
                    m.area_code, m.word, m.bit, query.elements, query.count,
                    static_cast<int>(query.format), query.bits, query.wide);
    return find_or_make(std::move(key), [&] { return Watch(target, query); });
}

std::shared_ptr<Watch> Watches::topic(const server::ControlTarget& target, std::string_view topic) {
    auto key = fmt::format("{}|topic|{}", static_cast<const void*>(&target), topic);
    return find_or_make(std::move(key), [&] { return Watch(target, std::string(topic)); });
}

void Watches::touch_topics() {
    for (const auto& [key, weak] : watches_)
        if (const auto w = weak.lock(); w != nullptr && w->topic()) w->touch();
}

std::size_t Watches::size() {
    std::erase_if(watches_, [](const auto& kv) { return kv.second.expired(); });
    return watches_.size();
}

}  // namespace fins::web
