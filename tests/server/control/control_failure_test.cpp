// The control channel's failure boundary (control_dispatch.hpp, issue 25): a request whose
// verb throws (std::bad_alloc, nlohmann::json's exceptions, std::out_of_range, anything)
// answers {"error":"internal error: ..."}, counts in fins_control_failures_total, and the
// channel (the same connection too) serves the next request. The test seam makes the
// throw; without the boundary it leaves io_context::run and finsd is gone.
#include <gtest/gtest.h>

#include <array>
#include <atomic>
#include <new>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include <boost/asio/io_context.hpp>
#include <boost/asio/post.hpp>
#include <nlohmann/json.hpp>

#include "plc/plc.hpp"
#include "server/control/control.hpp"
#include "server/control/control_client.hpp"
#include "server/control/control_dispatch.hpp"
#include "server/metrics/metrics.hpp"
#include "transport/asio.hpp"

namespace fins::test {
namespace {

using Json = nlohmann::json;

enum class Throw : int { nothing, bad_alloc, json, out_of_range, no_std_type };
constexpr std::array kinds{Throw::bad_alloc, Throw::json, Throw::out_of_range, Throw::no_std_type};

std::atomic<Throw> thrown{Throw::nothing};

void fault(const Json&) {
    switch (thrown.load()) {
        case Throw::nothing:
            return;
        case Throw::bad_alloc:
            throw std::bad_alloc();
        case Throw::json: {
            const Json number = 1;
            (void)number.at("key");  // type_error 304
            return;
        }
        case Throw::out_of_range: {
            const std::vector<int> none;
            (void)none.at(3);
            return;
        }
        case Throw::no_std_type:
            throw 42;
    }
}

std::uint64_t failures() {
    return server::metrics::process_metrics().control_failures.load();
}

class ControlFailure : public ::testing::Test {
  protected:
    void SetUp() override {
        server::set_control_fault_for_tests(fault);
        path_ = socket_path();
        auto s = server::ControlServer::start(io_, plc_, path_);
        ASSERT_TRUE(s) << s.error().message();
        server_ = std::move(*s);
        thread_ = std::thread([this] { io_.run(); });
    }
    void TearDown() override {
        if (thread_.joinable()) {
            asio::post(io_, [this] {
                server_->stop();
                io_.stop();
            });
            thread_.join();
        }
        thrown = Throw::nothing;
        server::set_control_fault_for_tests(nullptr);
    }

    asio::io_context io_{1};
    plc::Plc plc_;
    std::filesystem::path path_;
    std::unique_ptr<server::ControlServer> server_;
    std::thread thread_;
};

TEST_F(ControlFailure, EachKindOfThrowAnswersAnInternalErrorAndTheConnectionGoesOn) {
    ControlClient c(path_);
    ASSERT_TRUE(c.connected());
    for (const auto kind : kinds) {
        SCOPED_TRACE(static_cast<int>(kind));
        thrown = kind;
        const auto before = failures();
        const Json j = c.request(R"({"cmd":"mode","mode":"program"})");
        ASSERT_TRUE(j.is_object()) << j.dump();
        ASSERT_TRUE(j.contains("error")) << j.dump();
        EXPECT_EQ(j["error"].get<std::string>().rfind("internal error: ", 0), 0u) << j.dump();
        EXPECT_EQ(failures(), before + 1);
        // Nothing of the request was done, and the same connection answers the next one.
        thrown = Throw::nothing;
        const Json s = c.request(R"({"cmd":"status"})");
        EXPECT_EQ(s["ok"], true) << s.dump();
        EXPECT_EQ(s["status"]["mode"], "run");
    }
    EXPECT_NE(c.request(R"({"cmd":"mode","mode":"program"})").dump().find("\"ok\":true"),
              std::string::npos);
}

TEST_F(ControlFailure, WhatTheMessageSays) {
    ControlClient c(path_);
    thrown = Throw::bad_alloc;
    EXPECT_EQ(c.request(R"({"cmd":"status"})")["error"], "internal error: std::bad_alloc (out of memory)");
    thrown = Throw::no_std_type;
    EXPECT_EQ(c.request(R"({"cmd":"status"})")["error"], "internal error: an exception of no std type");
}

TEST_F(ControlFailure, AMistypedKeyIsTheClientsMistakeNotAFailure) {
    ControlClient c(path_);
    const auto before = failures();
    // "mode" must be a string: nlohmann's type_error inside the verb is a bad request.
    const Json j = c.request(R"({"cmd":"mode","mode":5})");
    ASSERT_TRUE(j.contains("error")) << j.dump();
    EXPECT_EQ(j["error"].get<std::string>().find("internal error"), std::string::npos) << j.dump();
    EXPECT_EQ(failures(), before);
}

TEST_F(ControlFailure, EveryConnectionIsStillServedAfterManyFailures) {
    thrown = Throw::out_of_range;
    const auto before = failures();
    for (int i = 0; i < 50; ++i) {
        ControlClient c(path_);
        ASSERT_TRUE(c.request(R"({"cmd":"status"})").contains("error"));
    }
    EXPECT_EQ(failures(), before + 50);
    thrown = Throw::nothing;
    ControlClient c(path_);
    EXPECT_EQ(c.request(R"({"cmd":"status"})")["ok"], true);
}

}  // namespace
}  // namespace fins::test
