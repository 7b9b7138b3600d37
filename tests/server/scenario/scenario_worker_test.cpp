// finsd's scenario thread (server/scenario/scenario_worker.hpp): jobs computed there and
// finished on the io_context's thread exactly once; settle() for control verbs; a worker
// destroyed with work queued; a ScenarioRunner whose real-time ticks go through it.
#include "server/scenario/scenario_worker.hpp"

#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <thread>
#include <vector>

#include <boost/asio/executor_work_guard.hpp>

#include "plc/plc.hpp"
#include "scenario/scenario.hpp"
#include "server/scenario/scenario_runner.hpp"

namespace fins::server {
namespace {

using namespace std::chrono_literals;

struct RecordingJob final : ScenarioWorker::Job {
    std::atomic<int> computed{0};
    std::atomic<bool> started{false};
    std::atomic<bool> release{true};  // compute waits while false (bounded)
    std::thread::id compute_thread;
    int finished = 0;
    std::thread::id finish_thread;

    void compute() noexcept override {
        started = true;
        for (int i = 0; i < 2000 && !release; ++i)
            std::this_thread::sleep_for(1ms);
        compute_thread = std::this_thread::get_id();
        ++computed;
    }
    void finish() noexcept override {
        ++finished;
        finish_thread = std::this_thread::get_id();
    }
};

// Runs `io` until `done()` or about 5 s (kept waiting while it has no handler ready:
// the worker's hand-backs come from another thread).
template <class F>
bool run_until(asio::io_context& io, F done) {
    auto guard = asio::make_work_guard(io);
    for (int i = 0; i < 500 && !done(); ++i) {
        io.restart();
        io.run_for(10ms);
    }
    return done();
}

// Runs `io` for `time`, waiting for handlers other threads post.
void run_for(asio::io_context& io, std::chrono::milliseconds time) {
    auto guard = asio::make_work_guard(io);
    io.restart();
    io.run_for(time);
}

TEST(ScenarioWorker, EveryJobIsComputedOnTheWorkerAndFinishedOnceOnTheIoThread) {
    asio::io_context io;
    ScenarioWorker worker(io);
    std::vector<RecordingJob> jobs(200);
    for (auto& job : jobs)
        worker.submit(job);
    ASSERT_TRUE(run_until(io, [&] {
        for (const auto& job : jobs)
            if (job.finished == 0) return false;
        return true;
    }));
    run_for(io, 20ms);  // nothing more comes back
    for (const auto& job : jobs) {
        EXPECT_EQ(job.computed, 1);
        EXPECT_EQ(job.finished, 1);
        EXPECT_NE(job.compute_thread, std::this_thread::get_id());
        EXPECT_EQ(job.finish_thread, std::this_thread::get_id());
    }
    EXPECT_EQ(worker.computed(), 200u);
}

TEST(ScenarioWorker, SettleComputesAJobNotYetHandedOverAndDropsItsFinish) {
    asio::io_context io;
    ScenarioWorker worker(io);
    RecordingJob job;
    worker.submit(job);
    worker.settle(job);  // before the hand-over ran
    EXPECT_EQ(job.computed, 1);
    EXPECT_EQ(job.compute_thread, std::this_thread::get_id());
    run_for(io, 30ms);
    EXPECT_EQ(job.computed, 1);
    EXPECT_EQ(job.finished, 0);
}

TEST(ScenarioWorker, SettleWaitsForAJobBeingComputedAndDropsItsFinish) {
    asio::io_context io;
    ScenarioWorker worker(io);
    RecordingJob job;
    job.release = false;
    worker.submit(job);
    ASSERT_TRUE(run_until(io, [&] { return job.started.load(); }));
    std::thread releaser([&] {
        std::this_thread::sleep_for(20ms);
        job.release = true;
    });
    worker.settle(job);  // returns only once compute() has
    EXPECT_EQ(job.computed, 1);
    releaser.join();
    run_for(io, 30ms);
    EXPECT_EQ(job.finished, 0);
}

TEST(ScenarioWorker, DestroyedWithJobsQueuedItStopsCleanly) {
    asio::io_context io;
    std::vector<RecordingJob> jobs(50);
    {
        ScenarioWorker worker(io);
        jobs[0].release = false;  // holds the thread while the rest wait in the queue
        for (auto& job : jobs)
            worker.submit(job);
        ASSERT_TRUE(run_until(io, [&] { return jobs[0].started.load(); }));
        jobs[0].release = true;
    }
    run_for(io, 20ms);  // a hand-back posted before the end finds the worker stopped
    int computed = 0;
    for (const auto& job : jobs) {
        computed += job.computed;
        EXPECT_EQ(job.finished, 0);
    }
    EXPECT_GE(computed, 1);  // the one it held; the queued ones may or may not have run
}

scenario::ScenarioDef counting(double tick_s) {
    scenario::ScenarioDef def;
    def.tick_s = tick_s;
    scenario::TagDef c;
    c.address.text = "D10";
    c.kind = scenario::SignalKind::counter;
    c.type = scenario::ValueType::uint16;
    c.input.text = "1";
    c.rate = 1 / tick_s;  // + 1 a tick
    def.tags.push_back(c);
    return def;
}

TEST(ScenarioWorker, ARunnersRealTimeTicksAreComputedThereAndPauseSettles) {
    asio::io_context io;
    ScenarioWorker worker(io);
    plc::Plc plc;
    auto compiled = scenario::Scenario::compile(counting(0.005), plc);
    ASSERT_TRUE(compiled);
    ScenarioRunner runner(io, std::move(*compiled), {}, "test", &worker);
    runner.start();
    ASSERT_TRUE(run_until(io, [&] { return runner.scenario().ticks() >= 6; }));
    EXPECT_GE(worker.computed(), 4u);  // the first tick runs at start, on this thread
    runner.pause();
    const auto ticks = runner.scenario().ticks();
    EXPECT_EQ(plc.memory().words(Region::dm)[10], ticks);  // ended ticks are in memory
    run_for(io, 30ms);
    EXPECT_EQ(runner.scenario().ticks(), ticks);
    EXPECT_EQ(plc.memory().words(Region::dm)[10], ticks);
    runner.stop();
}

}  // namespace
}  // namespace fins::server
