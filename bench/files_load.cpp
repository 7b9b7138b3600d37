// fins_files_load: a 1 MiB file put and get through finsd over FINS/UDP with the
// libfins helpers (22 03 / 22 02 chunks, 8 in flight), against a raw loopback UDP echo
// of the same frame sizes and the same window in the same run. The ratio says what
// finsd's file memory, the codec and the client cost over the kernel's loopback.
//
// finsd runs in this process on its own thread with a data directory under $TMPDIR;
// the echo server runs on another thread. Timing lives here, never in tests.
//
// With --loss or --reorder, put_file runs instead through a loopback LossyUdpProxy
// (tests/client/lossy_proxy.hpp) that drops (--loss) and holds back (--reorder, up to
// 60 ms, so later datagrams overtake) that fraction of the datagrams each way, with
// --retries (--proxy: through it without faults); the file is then read back over a
// direct client and compared.
#include <arpa/inet.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <array>
#include <atomic>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <random>
#include <span>
#include <thread>
#include <vector>

#include <fmt/core.h>
#include <spdlog/spdlog.h>
#include <CLI/CLI.hpp>
#include <boost/asio/io_context.hpp>

#include "fins/client.hpp"
#include "fins/commands/file_memory.hpp"
#include "plc/plc.hpp"
#include "server/sessions/server.hpp"

#include "client/lossy_proxy.hpp"
#include "echo_server.hpp"
#include "transport/asio.hpp"

namespace {

using Clock = std::chrono::steady_clock;

int connect_udp(std::uint16_t port) {
    const int fd = ::socket(AF_INET, SOCK_DGRAM, 0);
    sockaddr_in a{};
    a.sin_family = AF_INET;
    a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    a.sin_port = htons(port);
    ::connect(fd, reinterpret_cast<sockaddr*>(&a), sizeof a);
    // A lost datagram ends the run (reported as a failure), never hangs it.
    timeval tv{2, 0};
    setsockopt(fd, SOL_SOCKET, SO_RCVTIMEO, &tv, sizeof tv);
    return fd;
}

// The same blocking generator for the echo and for finsd: `frame(i)` is request i,
// `window` in flight. Seconds, or a negative value when an answer is missing or (for
// finsd, `check`) carries an end code other than 0000.
template <class FrameOf>
double drive(std::uint16_t port, std::size_t count, std::size_t window, FrameOf frame, bool check) {
    const int fd = connect_udp(port);
    std::array<std::uint8_t, 4096> buf{};
    const auto start = Clock::now();
    std::size_t sent = 0;
    std::size_t received = 0;
    bool ok = true;
    while (received < count && ok) {
        while (sent < count && sent - received < window) {
            const auto request = frame(sent);
            ::send(fd, request.data(), request.size(), 0);
            ++sent;
        }
        const auto n = ::recv(fd, buf.data(), buf.size(), 0);
        if (n <= 0) ok = false;
        // The end code follows the 10-byte header and the 2-byte command code.
        if (check && (n < 14 || buf[12] != 0 || (buf[13] & 0x3F) != 0)) ok = false;
        ++received;
    }
    const double s = std::chrono::duration<double>(Clock::now() - start).count();
    ::close(fd);
    return ok ? s : -1;
}

// `count` requests of `request_size` bytes, `window` in flight, to the echo: seconds.
double drive_echo(std::size_t request_size, std::size_t reply_size, std::size_t count,
                  std::size_t window) {
    // One recvfrom and one sendto per datagram (fins_load --udp-echo per-datagram).
    fins_bench::EchoServer echo(false, request_size, reply_size, {.udp_batched = false});
    const std::vector<std::uint8_t> request(request_size, 0x80);
    return drive(
        echo.port(), count, window, [&](std::size_t) { return fins::Bytes{request}; }, false);
}

// Pre-encoded 22 03 (put: the first chunk 0001, the rest 0002 append) and 22 02 (get)
// frames, as put_file/get_file send them, for the raw generator.
std::vector<std::vector<std::uint8_t>> encode_frames(std::span<const std::uint8_t> data,
                                                     const fins::FileName& name, bool put) {
    std::vector<std::vector<std::uint8_t>> frames;
    const std::size_t chunk = put ? fins::max_parameter_size - 24 : fins::max_file_read_bytes;
    for (std::size_t offset = 0, i = 0; offset < data.size(); offset += chunk, ++i) {
        const std::size_t n = std::min(chunk, data.size() - offset);
        std::array<std::uint8_t, fins::max_parameter_size> params{};
        fins::ByteWriter w{params};
        if (put) {
            fins::SingleFileWrite c;
            c.mode = static_cast<std::uint16_t>(i == 0 ? fins::FileWriteMode::create_or_replace
                                                       : fins::FileWriteMode::append);
            c.file = name;
            c.data = data.subspan(offset, n);
            c.encode(w);
        } else {
            fins::SingleFileRead c;
            c.file = name;
            c.position = static_cast<std::uint32_t>(offset);
            c.length = static_cast<std::uint16_t>(n);
            c.encode(w);
        }
        fins::Header h;
        h.destination = {0, 1, 0};
        h.source = {0, 200, 0};
        h.service_id = static_cast<std::uint8_t>(i);
        std::vector<std::uint8_t> out(fins::max_frame_size);
        const auto code = put ? fins::SingleFileWrite::code : fins::SingleFileRead::code;
        out.resize(fins::encode_request(h, code, w.written(), out).value_or(0));
        frames.push_back(std::move(out));
    }
    return frames;
}

struct Lossy {
    double loss = 0;
    double reorder = 0;
    unsigned retries = 8;
    unsigned timeout_ms = 100;
    bool proxy = false;  // through the proxy even without faults (the 0 % reference)
};

// put_file of `data` through the proxy, then get_file over `direct`: 0 when every round's
// file is identical.
int lossy_rounds(std::uint16_t server_port, fins::Client& direct,
                 const std::vector<std::uint8_t>& data, const fins::FileName& name,
                 std::size_t window, unsigned rounds, const Lossy& l, bool json) {
    int status = 0;
    for (unsigned round = 0; round < rounds; ++round) {
        fins::test::Faults faults;
        faults.drop = l.loss;
        faults.duplicate = 0;
        faults.delay = l.reorder;
        faults.seed = round + 1;
        fins::test::LossyUdpProxy proxy(server_port, faults);
        fins::ClientOptions o;
        o.port = proxy.port();
        o.retries = l.retries;
        o.timeout = std::chrono::milliseconds(l.timeout_ms);
        auto client = fins::Client::connect(o);
        if (!client) return 1;
        const auto t0 = Clock::now();
        auto put =
            fins::put_file(**client, fins::disk_memory_card, "", name, data, true, {}, window);
        const double put_s = std::chrono::duration<double>(Clock::now() - t0).count();
        auto got = fins::get_file(direct, fins::disk_memory_card, "", name, {}, window);
        const bool identical = put && got && *got == data;
        if (!identical) status = 1;
        const auto c = proxy.counts();
        const auto st = (*client)->stats();
        const double mb = static_cast<double>(data.size()) / 1e6;
        if (json)
            fmt::print(
                "{{\"round\":{},\"loss\":{},\"reorder\":{},\"put_s\":{:.3f},"
                "\"put_mbps\":{:.2f},\"ok\":{},\"identical\":{},\"dropped\":{},"
                "\"delayed\":{},\"forwarded\":{},\"sent\":{},\"retransmitted\":{}}}\n",
                round, l.loss, l.reorder, put_s, mb / put_s, put.has_value(), identical, c.dropped,
                c.delayed, c.forwarded, st.sent, st.retransmitted);
        else
            fmt::print(
                "round {}: put {:.3f} s ({:.1f} MB/s) through {:.0f} % loss, {:.0f} % "
                "held back: {}, file {}; proxy dropped {}, held back {}, passed {}; client sent "
                "{}, re-sent {}\n",
                round, put_s, mb / put_s, l.loss * 100, l.reorder * 100, put ? "ok" : "FAILED",
                identical ? "identical" : "DIFFERENT", c.dropped, c.delayed, c.forwarded, st.sent,
                st.retransmitted);
    }
    return status;
}

}  // namespace

int main(int argc, char** argv) {
    CLI::App app{"fins_files_load: 1 MiB file put/get through finsd vs a raw loopback echo"};
    std::size_t bytes = 1 << 20;
    std::size_t window = 8;
    unsigned rounds = 3;
    bool json = false;
    app.add_option("--bytes", bytes, "File size")->capture_default_str();
    app.add_option("--window", window, "Chunks in flight")->capture_default_str();
    app.add_option("--rounds", rounds, "Put/get rounds")->capture_default_str();
    app.add_flag("--json", json, "Print JSON lines");
    Lossy lossy;
    app.add_option("--loss", lossy.loss, "Put through a proxy dropping this fraction each way")
        ->check(CLI::Range(0.0, 0.5));
    app.add_option("--reorder", lossy.reorder,
                   "Put through a proxy holding back this fraction (up to 60 ms)")
        ->check(CLI::Range(0.0, 0.5));
    app.add_flag("--proxy", lossy.proxy, "Put through the proxy also without --loss/--reorder");
    app.add_option("--retries", lossy.retries, "Client retries with --loss/--reorder")
        ->capture_default_str()
        ->check(CLI::Range(0, 15));
    app.add_option("--timeout-ms", lossy.timeout_ms, "Client timeout with --loss/--reorder")
        ->capture_default_str()
        ->check(CLI::Range(10, 2000));
    CLI11_PARSE(app, argc, argv);
    spdlog::set_level(spdlog::level::warn);

    const auto root =
        std::filesystem::temp_directory_path() / fmt::format("fins-files-load-{}", ::getpid());
    fins::plc::Plc plc{fins::plc::cj2h()};
    if (!plc.files().attach(root)) return 1;
    asio::io_context io{1};
    fins::server::ServerOptions options;
    options.port = 0;
    auto server = fins::server::Server::start(io, plc, options);
    if (!server) return 1;
    std::thread server_thread([&] { io.run(); });

    fins::ClientOptions o;
    o.port = (*server)->udp_port();
    auto client = fins::Client::connect(o);
    if (!client) return 1;
    std::vector<std::uint8_t> data(bytes);
    std::mt19937 gen(1);
    for (auto& b : data)
        b = static_cast<std::uint8_t>(gen());
    const auto name = *fins::FileName::from("BENCH.BIN");

    // Frame sizes as they cross the wire (FINS header 10 + command code 2 ...).
    const std::size_t put_chunk = fins::max_parameter_size - 24;
    const std::size_t put_request = 12 + 24 + put_chunk, put_reply = 14;
    const std::size_t get_request = 12 + 22, get_reply = 14 + 10 + fins::max_file_read_bytes;
    const std::size_t put_count = (bytes + put_chunk - 1) / put_chunk;
    const std::size_t get_count =
        (bytes + fins::max_file_read_bytes - 1) / fins::max_file_read_bytes;
    const double mb = static_cast<double>(bytes) / 1e6;

    const auto put_frames = encode_frames(data, name, true);
    const auto get_frames = encode_frames(data, name, false);
    if (lossy.proxy || lossy.loss > 0 || lossy.reorder > 0) {
        const int status =
            lossy_rounds((*server)->udp_port(), **client, data, name, window, rounds, lossy, json);
        (*server)->stop();
        io.stop();
        server_thread.join();
        std::error_code ec;
        std::filesystem::remove_all(root, ec);
        return status;
    }
    for (unsigned round = 0; round < rounds; ++round) {
        auto t0 = Clock::now();
        auto put =
            fins::put_file(**client, fins::disk_memory_card, "", name, data, true, {}, window);
        const double put_s = std::chrono::duration<double>(Clock::now() - t0).count();
        t0 = Clock::now();
        auto got = fins::get_file(**client, fins::disk_memory_card, "", name, {}, window);
        const double get_s = std::chrono::duration<double>(Clock::now() - t0).count();
        if (!put || !got || *got != data) {
            std::fprintf(stderr, "fins_files_load: transfer failed\n");
            return 1;
        }
        // The raw generator against finsd: the same frames put_file/get_file send, from
        // the echo's blocking loop, so the ratio to the echo is finsd's own cost.
        const double raw_put =
            drive((*server)->udp_port(), put_frames.size(), window,
                  [&](std::size_t i) { return fins::Bytes{put_frames[i]}; }, true);
        const double raw_get =
            drive((*server)->udp_port(), get_frames.size(), window,
                  [&](std::size_t i) { return fins::Bytes{get_frames[i]}; }, true);
        if (raw_put < 0 || raw_get < 0) {
            std::fprintf(stderr, "fins_files_load: a raw 22 02/22 03 frame failed\n");
            return 1;
        }
        const double echo_put = drive_echo(put_request, put_reply, put_count, window);
        const double echo_get = drive_echo(get_request, get_reply, get_count, window);
        if (json)
            fmt::print(
                "{{\"round\":{},\"put_mbps\":{:.2f},\"raw_put_mbps\":{:.2f},"
                "\"echo_put_mbps\":{:.2f},\"put_ratio\":{:.2f},\"raw_put_ratio\":{:.2f},"
                "\"get_mbps\":{:.2f},\"raw_get_mbps\":{:.2f},\"echo_get_mbps\":{:.2f},"
                "\"get_ratio\":{:.2f},\"raw_get_ratio\":{:.2f}}}\n",
                round, mb / put_s, mb / raw_put, mb / echo_put, echo_put / put_s,
                echo_put / raw_put, mb / get_s, mb / raw_get, mb / echo_get, echo_get / get_s,
                echo_get / raw_get);
        else
            fmt::print(
                "round {}: put {:6.1f} MB/s libfins (ratio {:.2f}), {:6.1f} raw (ratio {:.2f}), "
                "echo {:6.1f} | get {:6.1f} libfins (ratio {:.2f}), {:6.1f} raw (ratio {:.2f}), "
                "echo {:6.1f}\n",
                round, mb / put_s, echo_put / put_s, mb / raw_put, echo_put / raw_put,
                mb / echo_put, mb / get_s, echo_get / get_s, mb / raw_get, echo_get / raw_get,
                mb / echo_get);
    }
    (*server)->stop();
    io.stop();
    server_thread.join();
    std::error_code ec;
    std::filesystem::remove_all(root, ec);
    return 0;
}
