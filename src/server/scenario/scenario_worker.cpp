// The scenario compute thread (contract in scenario_worker.hpp).
#include "server/scenario/scenario_worker.hpp"

#ifdef _WIN32
#include <windows.h>
#else
#include <pthread.h>
#include <sys/resource.h>
#include <sys/syscall.h>
#include <unistd.h>
#endif

#include <algorithm>
#include <atomic>

#include <boost/asio/post.hpp>

namespace fins::server {

// What the worker thread and the io_context's handlers share; a handler posted before the
// worker was destroyed keeps it alive and finds `stopping` set.
struct ScenarioWorker::Shared {
    std::mutex mutex;
    std::condition_variable wake;     // the worker: a job or stop
    std::condition_variable settled;  // settle(): the job being computed is done
    std::deque<Job*> queue;
    Job* computing = nullptr;
    std::vector<Job*> done;  // computed, finish() not yet run
    bool hand_back_posted = false;
    std::atomic<bool> stopping{false};
    std::uint64_t computed = 0;
};

ScenarioWorker::ScenarioWorker(asio::io_context& io)
    : io_(io), shared_(std::make_shared<Shared>()), thread_([this] { run(); }) {}

ScenarioWorker::~ScenarioWorker() {
    {
        std::lock_guard lock(shared_->mutex);
        shared_->stopping = true;
        shared_->queue.clear();
        shared_->done.clear();
    }
    shared_->wake.notify_all();
    thread_.join();
}

void ScenarioWorker::submit(Job& job) {
    // Collected on this thread and handed over in one go after the handlers ready now
    // (a phase group's timers expire together): one lock and one wakeup per group.
    submitted_.push_back(&job);
    if (hand_over_posted_) return;
    hand_over_posted_ = true;
    asio::post(io_, [this, shared = shared_] {
        if (shared->stopping) return;
        hand_over();
    });
}

void ScenarioWorker::hand_over() {
    hand_over_posted_ = false;
    if (submitted_.empty()) return;
    {
        std::lock_guard lock(shared_->mutex);
        shared_->queue.insert(shared_->queue.end(), submitted_.begin(), submitted_.end());
    }
    submitted_.clear();
    shared_->wake.notify_one();
}

void ScenarioWorker::settle(Job& job) {
    if (const auto it = std::find(submitted_.begin(), submitted_.end(), &job);
        it != submitted_.end()) {
        submitted_.erase(it);
        job.compute();
        return;
    }
    std::unique_lock lock(shared_->mutex);
    auto& q = shared_->queue;
    if (const auto it = std::find(q.begin(), q.end(), &job); it != q.end()) {
        q.erase(it);
        lock.unlock();
        job.compute();
        return;
    }
    shared_->settled.wait(lock, [&] { return shared_->computing != &job; });
    auto& d = shared_->done;
    d.erase(std::remove(d.begin(), d.end(), &job), d.end());
}

std::uint64_t ScenarioWorker::computed() const {
    std::lock_guard lock(shared_->mutex);
    return shared_->computed;
}

void ScenarioWorker::run() {
    // Below the I/O thread (Linux: a thread's own nice value): when both want a core the
    // requests go first, and the ticks take the idle time between them; at nice 10 the
    // thread still gets about a tenth of a contended core, more than ticks need.
#ifdef _WIN32
    // Windows: the thread priority below normal, the same rule.
    ::SetThreadPriority(::GetCurrentThread(), THREAD_PRIORITY_BELOW_NORMAL);
#else
    setpriority(PRIO_PROCESS, static_cast<id_t>(::syscall(SYS_gettid)), worker_nice);
    // Named, so that `top -H` and `ps -L` tell it from the I/O thread.
    pthread_setname_np(pthread_self(), thread_name);
#endif
    Shared& s = *shared_;
    std::unique_lock lock(s.mutex);
    for (;;) {
        s.wake.wait(lock, [&] { return s.stopping || !s.queue.empty(); });
        if (s.stopping) return;
        Job* job = s.queue.front();
        s.queue.pop_front();
        s.computing = job;
        // Under the lock: a queued job may be settled and destroyed by its owner as soon
        // as the lock is free.
        if (!s.queue.empty()) s.queue.front()->prefetch();
        lock.unlock();
        job->compute();
        lock.lock();
        s.computing = nullptr;
        ++s.computed;
        s.done.push_back(job);
        s.settled.notify_all();
        if (s.hand_back_posted || (!s.queue.empty() && s.done.size() < hand_back_batch)) continue;
        s.hand_back_posted = true;
        // One handler takes every job finished by the time it runs.
        asio::post(io_, [shared = shared_] {
            std::vector<Job*> finished;
            {
                std::lock_guard guard(shared->mutex);
                shared->hand_back_posted = false;
                if (shared->stopping) return;
                finished.swap(shared->done);
            }
            for (Job* j : finished)
                j->finish();
        });
    }
}

}  // namespace fins::server
