// One timer for every scenario tick due on an io_context (issue 19): a plant's units tick
// in phase groups (ScenarioRunner::phase_of), and the units of a group are due at the same
// instant. With a steady_timer per unit, 1,000 units meant 1,000 timer expiries, heap
// operations and handler allocations per period; here a group is one expiry, and a unit's
// schedule is a push onto its group's list. An io_context service: every ScenarioRunner
// of an io_context shares the one (asio::use_service), with no change to who builds them.
// Everything runs on the io_context's thread.
#pragma once

#include <chrono>
#include <cstdint>
#include <map>
#include <vector>

#include <boost/asio/execution_context.hpp>
#include <boost/asio/io_context.hpp>
#include <boost/asio/steady_timer.hpp>

#include "transport/asio.hpp"

namespace fins::server {

class ScenarioTicker final : public asio::execution_context::service {
  public:
    using Clock = std::chrono::steady_clock;
    // What is due: called once per schedule(), at or after its time, on the io_context's
    // thread (never from inside schedule() or cancel()).
    class Client {
      public:
        virtual void due() noexcept = 0;
        // Asks for the lines due() reads first (a hint: the ticker calls it for the next
        // client of an expiry while this one runs).
        virtual void prefetch() const noexcept {}

      protected:
        ~Client() = default;

      private:
        friend class ScenarioTicker;
        enum class Place : std::uint8_t { none, due, running };
        Place place_ = Place::none;  // in due_ (at at_), in running_, or neither
        Clock::time_point at_{};
    };

    using key_type = ScenarioTicker;
    static inline asio::execution_context::id id;

    // Made by asio::use_service<ScenarioTicker>(io_context&) only.
    explicit ScenarioTicker(asio::execution_context& context);

    // `client` is due at `at` (a client is due at one time at most: this replaces its
    // earlier schedule, if any).
    void schedule(Client& client, Clock::time_point at);
    // `client` is not due any more (also before it is destroyed).
    void cancel(Client& client) noexcept;

    // Clients scheduled and not yet called (tests).
    [[nodiscard]] std::size_t pending() const noexcept;
    // Timer expiries so far (tests: one per instant, however many clients are due then).
    [[nodiscard]] std::uint64_t expiries() const noexcept { return expiries_; }

  private:
    void shutdown() override;
    void arm();
    void expire(boost::system::error_code ec);

    asio::steady_timer timer_;
    // Clients by due time: a group's units share one entry.
    std::map<Clock::time_point, std::vector<Client*>> due_;
    Clock::time_point armed_ = Clock::time_point::max();
    // The clients of the expiry being run (a cancel during it clears its entry).
    std::vector<Client*> running_;
    // Lists of expired entries, kept for the next new entries (no allocation per period).
    std::vector<std::vector<Client*>> spare_;
    static constexpr std::size_t max_spare = 64;
    std::uint64_t expiries_ = 0;
};

}  // namespace fins::server
