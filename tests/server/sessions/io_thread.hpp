// Servers under test on one I/O thread of their own, as finsd runs them: every call into
// them is posted to that thread and waited for, each wait bounded.
#pragma once

#include <gtest/gtest.h>

#include <chrono>
#include <future>
#include <memory>
#include <thread>

#include <boost/asio/io_context.hpp>
#include <boost/asio/post.hpp>

#include "server/sessions/server.hpp"
#include "transport/asio.hpp"

namespace fins::test {

class IoThread {
  public:
    // A derived fixture calls stop() in its own destructor, before its servers go.
    ~IoThread() { stop(); }

    void start_thread() {
        thread_ = std::thread([this] { io.run(); });
    }
    void stop() {
        io.stop();
        if (thread_.joinable()) thread_.join();
    }

    // f() on the I/O thread; its result (at most 10 s).
    template <typename F>
    auto on_io(F f) {
        std::packaged_task<decltype(f())()> task(std::move(f));
        auto result = task.get_future();
        asio::post(io, [&task] { task(); });
        EXPECT_EQ(result.wait_for(std::chrono::seconds(10)), std::future_status::ready);
        return result.get();
    }

    // Polls `done` on the I/O thread every 10 ms until it holds, at most 500 times.
    template <typename F>
    bool wait(F done) {
        for (int i = 0; i < 500; ++i) {
            if (on_io(done)) return true;
            std::this_thread::sleep_for(std::chrono::milliseconds(10));
        }
        return false;
    }

    // Runs a Send/Rcv/SendCmd instruction on `node`; its result (at most 10 s).
    server::InstructionResult run(server::Server& node, server::InstructionRequest request) {
        auto done = std::make_shared<std::promise<server::InstructionResult>>();
        auto result = done->get_future();
        asio::post(io, [&node, request, done] {
            node.instructions().start(
                request, [done](const server::InstructionResult& r) { done->set_value(r); });
        });
        EXPECT_EQ(result.wait_for(std::chrono::seconds(10)), std::future_status::ready);
        return result.get();
    }

    asio::io_context io{1};

  private:
    std::thread thread_;
};

}  // namespace fins::test
