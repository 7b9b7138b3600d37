// Google Benchmark micro-benchmarks of the hot path: decoding a request frame and
// running it through the dispatcher into a response buffer (no sockets).
#include <unistd.h>

#include <array>
#include <filesystem>
#include <string>

#include <benchmark/benchmark.h>

#include "fins/commands/memory_area.hpp"
#include "fins/frame.hpp"
#include "plc/plc.hpp"
#include "plc/profile.hpp"
#include "server/dispatch/dispatcher.hpp"

namespace {

std::array<std::uint8_t, fins::max_frame_size> make_read(std::uint16_t words, std::size_t& size) {
    std::array<std::uint8_t, 16> params{};
    fins::ByteWriter pw{params};
    fins::MemoryAreaRead{{0x82, 100, 0}, words}.encode(pw);
    fins::Header h;
    h.destination = {0, 1, 0};
    h.source = {0, 200, 0};
    std::array<std::uint8_t, fins::max_frame_size> frame{};
    size = fins::encode_request(h, fins::MemoryAreaRead::code, pw.written(), frame).value_or(0);
    return frame;
}

void BM_DecodeRequest(benchmark::State& state) {
    std::size_t size = 0;
    const auto frame = make_read(1, size);
    for (auto _ : state) {
        auto r = fins::decode_request(fins::Bytes{frame.data(), size});
        benchmark::DoNotOptimize(r);
    }
}
BENCHMARK(BM_DecodeRequest);

void BM_DispatchRead(benchmark::State& state) {
    fins::plc::Plc plc{fins::plc::cj2h()};
    fins::server::Dispatcher dispatcher{plc, {0, 1, 0}};
    std::size_t size = 0;
    const auto frame = make_read(static_cast<std::uint16_t>(state.range(0)), size);
    std::array<std::uint8_t, fins::max_frame_size> out{};
    const fins::server::RequestContext context{};
    for (auto _ : state) {
        auto n = dispatcher.handle(fins::Bytes{frame.data(), size}, out, context);
        benchmark::DoNotOptimize(n);
    }
}
BENCHMARK(BM_DispatchRead)->Arg(1)->Arg(999);

// A 1-word MEMORY AREA WRITE to D100 on a state file in $TMPDIR (or /tmp):
// arg 0 = [storage] durability "process", 1 = "power" (fdatasync before each answer).
void BM_DispatchWriteStateFile(benchmark::State& state) {
    const auto dir =
        std::filesystem::temp_directory_path() / ("finskit-bench-" + std::to_string(::getpid()));
    std::filesystem::remove_all(dir);
    {
        const auto durability =
            state.range(0) == 0 ? fins::plc::Durability::process : fins::plc::Durability::power;
        auto storage = fins::plc::Storage::open(dir, "cj2h", {durability});
        if (!storage) {
            state.SkipWithError(storage.error().message().c_str());
            return;
        }
        fins::plc::Plc plc{fins::plc::cj2h(), std::move(*storage)};
        if (!plc.storage().seal()) state.SkipWithError("seal failed");
        fins::server::Dispatcher dispatcher{plc, {0, 1, 0}};
        std::array<std::uint8_t, 16> params{0x82, 0x00, 0x64, 0x00, 0x00, 0x01, 0x00, 0x00};
        fins::Header h;
        h.destination = {0, 1, 0};
        h.source = {0, 200, 0};
        std::array<std::uint8_t, fins::max_frame_size> frame{};
        std::array<std::uint8_t, fins::max_frame_size> out{};
        const fins::server::RequestContext context{};
        std::uint16_t value = 0;
        for (auto _ : state) {
            params[7] = static_cast<std::uint8_t>(++value);  // a change every time
            const auto size =
                fins::encode_request(h, {0x01, 0x02}, fins::Bytes{params.data(), 8}, frame)
                    .value_or(0);
            auto n = dispatcher.handle(fins::Bytes{frame.data(), size}, out, context);
            benchmark::DoNotOptimize(n);
        }
    }
    std::filesystem::remove_all(dir);
}
BENCHMARK(BM_DispatchWriteStateFile)->Arg(0)->Arg(1)->UseRealTime();

}  // namespace
