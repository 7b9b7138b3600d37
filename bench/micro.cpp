// Google Benchmark micro-benchmarks of the hot path: decoding a request frame and
// running it through the dispatcher into a response buffer (no sockets).
#include <array>

#include <benchmark/benchmark.h>

#include "fins/commands/memory_area.hpp"
#include "fins/frame.hpp"
#include "plc/plc.hpp"
#include "plc/profile.hpp"
#include "server/dispatcher.hpp"

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

}  // namespace
