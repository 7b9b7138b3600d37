// One timer for every scenario tick due on an io_context (contract in scenario_ticker.hpp).
#include "server/scenario/scenario_ticker.hpp"

#include <algorithm>

namespace fins::server {

ScenarioTicker::ScenarioTicker(asio::execution_context& context)
    : asio::execution_context::service(context), timer_(static_cast<asio::io_context&>(context)) {}

void ScenarioTicker::schedule(Client& client, Clock::time_point at) {
    cancel(client);
    auto [entry, added] = due_.try_emplace(at);
    if (added && !spare_.empty()) {
        entry->second = std::move(spare_.back());
        spare_.pop_back();
    }
    entry->second.push_back(&client);
    client.place_ = Client::Place::due;
    client.at_ = at;
    if (at < armed_) arm();
}

void ScenarioTicker::cancel(Client& client) noexcept {
    std::vector<Client*>* list = nullptr;
    if (client.place_ == Client::Place::running) {
        list = &running_;
    } else if (client.place_ == Client::Place::due) {
        const auto entry = due_.find(client.at_);
        if (entry != due_.end()) list = &entry->second;
    }
    client.place_ = Client::Place::none;
    if (list == nullptr) return;
    // Cleared, not erased: an expiry may be walking running_, and an emptied entry
    // stays until it expires (the timer may be armed for it).
    const auto found = std::find(list->begin(), list->end(), &client);
    if (found != list->end()) *found = nullptr;
}

std::size_t ScenarioTicker::pending() const noexcept {
    std::size_t n = 0;
    for (const auto& [at, list] : due_)
        n += static_cast<std::size_t>(
            std::count_if(list.begin(), list.end(), [](const Client* c) { return c != nullptr; }));
    return n;
}

void ScenarioTicker::arm() {
    if (due_.empty()) {
        armed_ = Clock::time_point::max();
        timer_.cancel();
        return;
    }
    armed_ = due_.begin()->first;
    timer_.expires_at(armed_);
    timer_.async_wait([this](boost::system::error_code ec) { expire(ec); });
}

void ScenarioTicker::expire(boost::system::error_code ec) {
    if (ec) return;  // re-armed (a newer wait runs) or shut down
    ++expiries_;
    armed_ = Clock::time_point::max();
    const auto now = Clock::now();
    // Every entry due by now, in time order. A client that schedules again from due(),
    // even at a time already past, is run by the next expiry, after the handlers waiting
    // on the io_context (so no client can hold the thread in this loop).
    std::size_t entries = 0;
    for (auto it = due_.begin(); it != due_.end() && it->first <= now; ++it)
        ++entries;
    for (; entries > 0; --entries) {
        running_ = std::move(due_.begin()->second);
        due_.erase(due_.begin());
        for (Client* c : running_)
            if (c != nullptr) c->place_ = Client::Place::running;
        const std::size_t n = running_.size();
        for (std::size_t i = 0; i < n; ++i) {
            // A group's clients are cold by the time they are due (a period since their
            // last tick): their objects two ahead, what the next one's due() reads first
            // one ahead (from the object fetched at the step before).
            if (i + 2 < n && running_[i + 2] != nullptr) {
                const char* next = reinterpret_cast<const char*>(running_[i + 2]);
                __builtin_prefetch(next);
                __builtin_prefetch(next + 64);
                __builtin_prefetch(next + 128);
            }
            if (i + 1 < n && running_[i + 1] != nullptr) running_[i + 1]->prefetch();
            Client* c = running_[i];
            if (c == nullptr) continue;
            running_[i] = nullptr;
            c->place_ = Client::Place::none;
            c->due();
        }
        running_.clear();
        if (spare_.size() < max_spare) spare_.push_back(std::move(running_));
        running_ = {};
    }
    arm();
}

void ScenarioTicker::shutdown() {
    timer_.cancel();
    due_.clear();
    running_.clear();
    spare_.clear();
    armed_ = Clock::time_point::max();
}

}  // namespace fins::server
