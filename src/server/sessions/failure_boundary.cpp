// The request paths' failure boundary (contract in failure_boundary.hpp).
#include "server/sessions/failure_boundary.hpp"

#include <array>
#include <atomic>
#include <mutex>
#include <new>

#include <fmt/core.h>
#include <spdlog/spdlog.h>

#include "fins/frame.hpp"
#include "server/metrics/metrics.hpp"
#include "server/sessions/log_summary.hpp"

namespace fins::server {

namespace {

std::atomic<RequestFault> request_fault{nullptr};

// One LogSummary per channel; sessions of a test binary run on several threads.
struct FailureLog {
    std::mutex mutex;
    std::array<LogSummary, 2> channels;
};

FailureLog& failure_log() noexcept {
    static FailureLog log;
    return log;
}

constexpr std::size_t response_prefix_size = header_size + command_code_size + end_code_size;

}  // namespace

std::string describe_exception(const std::exception_ptr& e) {
    try {
        std::rethrow_exception(e);
    } catch (const std::bad_alloc&) {
        return "std::bad_alloc (out of memory)";
    } catch (const std::exception& x) {
        return x.what();
    } catch (...) {
        return "an exception of no std type";
    }
}

void note_failure(FailureChannel channel, std::string_view where, std::string_view what) noexcept {
    if (channel == FailureChannel::fins)
        metrics::note_request_failure();
    else
        metrics::note_control_failure();
    try {
        std::uint64_t n = 0;
        {
            std::lock_guard lock(failure_log().mutex);
            n = failure_log().channels[static_cast<std::size_t>(channel)].note();
        }
        const char* name = channel == FailureChannel::fins ? "fins" : "control";
        if (n == 0) {
            spdlog::debug("{}: {} failed: {}", name, where, what);
            return;
        }
        spdlog::error("{}: {} failed: {}{}", name, where, what,
                      n > 1 ? fmt::format(" (and {} more failures since the last such line)", n - 1)
                            : std::string());
    } catch (...) {
        // Out of memory for the log line itself: the counter has it.
    }
}

std::size_t handle_guarded(Dispatcher& dispatcher, Bytes request, MutableBytes out,
                           const RequestContext& context) noexcept {
    try {
        if (const auto fault = request_fault.load(std::memory_order_relaxed)) fault(request);
        return dispatcher.handle(request, out, context);
    } catch (...) {
        const auto e = std::current_exception();
        std::string what;
        try {
            what = describe_exception(e);
        } catch (...) {
            what = "an exception";
        }
        if (request.size() < header_size + command_code_size) {
            note_failure(FailureChannel::fins, "a FINS request", what);
            return 0;
        }
        ByteReader reader(request);
        const Header header = read_header(reader);
        const CommandCode command{reader.u8(), reader.u8()};
        try {
            note_failure(
                FailureChannel::fins,
                fmt::format("FINS command {:02X}{:02X} from {}.{}.{}", command.main, command.sub,
                            header.source.network, header.source.node, header.source.unit),
                what);
        } catch (...) {
            note_failure(FailureChannel::fins, "a FINS request", what);
        }
        if (header.is_response() || !header.response_required() ||
            out.size() < response_prefix_size)
            return 0;
        // W342 5-1-3 0301: an error in the unit that serves FINS (finsd itself).
        Header response = response_header(header, dispatcher.self());
        if (header.destination.node == broadcast_node)
            response.source.node = dispatcher.self().node;
        ByteWriter w(out);
        write_response_prefix(w, response, command,
                              static_cast<std::uint16_t>(EndCode::communications_controller_error));
        return w.overflowed() ? 0 : w.size();
    }
}

void set_request_fault_for_tests(RequestFault fault) noexcept {
    request_fault.store(fault, std::memory_order_relaxed);
}

}  // namespace fins::server
