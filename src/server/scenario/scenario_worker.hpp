// The thread that computes the scenario ticks of finsd's CPU Units (issue 19), so that a
// plant's ticks do not take the I/O thread's time from the requests it serves.
//
// The I/O thread owns every CPU Unit. A tick's hand-over per unit (Scenario's three
// phases): the I/O thread copies the words the unit's tags touch into the scenario's image
// (begin_tick) and submits the job (the jobs the handlers ready at the same time submit go
// over together: one wakeup of this thread per phase group); this thread computes every
// tag on the image (compute), touching nothing of the CPU Unit; the I/O thread copies the
// changed words back (end_tick, the job's finish()). Finished jobs go back in batches (when
// the queue runs empty, or every hand_back_batch jobs), one post to the io_context each,
// so a phase group costs the I/O thread a wakeup or two, not one per unit.
//
// Bounded: a job is queued at most once (its owner has at most one tick in flight), so the
// queue holds at most one entry per CPU Unit with a scenario.
#pragma once

#include <condition_variable>
#include <deque>
#include <memory>
#include <mutex>
#include <thread>
#include <vector>

#include <boost/asio/io_context.hpp>

#include "transport/asio.hpp"

namespace fins::server {

class ScenarioWorker {
  public:
    struct Job {
        virtual void compute() noexcept = 0;  // on the worker thread
        virtual void finish() noexcept = 0;   // on the io_context's thread, after compute
        // Asks for the lines compute() reads first (a hint, on the worker thread, for the
        // next queued job while one computes).
        virtual void prefetch() const noexcept {}

      protected:
        virtual ~Job() = default;
    };

    static constexpr std::size_t hand_back_batch = 64;
    // The thread's nice value (relative priority below the I/O thread's).
    static constexpr int worker_nice = 10;
    // The thread's name (at most 15 characters, as Linux allows).
    static constexpr const char* thread_name = "finsd-scenario";

    explicit ScenarioWorker(asio::io_context& io);
    ~ScenarioWorker();  // stops and joins the thread; jobs still queued are dropped
    ScenarioWorker(const ScenarioWorker&) = delete;
    ScenarioWorker& operator=(const ScenarioWorker&) = delete;

    // Queues `job`; its finish() runs on the io_context's thread after its compute().
    void submit(Job& job);
    // On the io_context's thread: returns once `job`'s compute() has run (now, on this
    // thread, if it was still queued) and drops its pending finish(): the caller finishes
    // it itself. For a job that was not submitted, returns at once.
    void settle(Job& job);

    // Jobs computed since start (for status and tests).
    [[nodiscard]] std::uint64_t computed() const;

  private:
    struct Shared;
    void run();
    void hand_over();
    asio::io_context& io_;
    // Submitted on the io_context's thread, not yet handed over (hand_over).
    std::vector<Job*> submitted_;
    bool hand_over_posted_ = false;
    std::shared_ptr<Shared> shared_;
    std::thread thread_;
};

}  // namespace fins::server
