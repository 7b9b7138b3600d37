// `fins discover --hosts RANGE`: which FINS nodes answer on an IPv4 range. Each host gets
// one 05 01 CPU UNIT DATA READ (W342 5-3-15, data 00: model and version) over UDP to
// node 00, "the local node" (W342 5-1-1 DA1), which a PLC answers from its own address,
// as `fins probe` does for one host. RANGE is a comma-separated list of
//   127.0.0.1             one host
//   127.0.0.1-127.0.0.9   a range (or 127.0.0.1-9: the last octet)
//   192.168.250.0/24      a CIDR block, /22 at most; /30 and wider skip the network and
//                         broadcast addresses
// with at most `max_hosts` hosts in all. At most --parallel requests are in flight; each
// host gets --timeout per attempt and --retries more attempts, so the run is bounded.
// Prints one line per node that answered (host, node, model, version) in RANGE's order; exit
// 0 when at least one did, 3 when none did.
#include <algorithm>
#include <array>
#include <chrono>
#include <deque>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include <fmt/core.h>

#include "cli/fins/commands.hpp"
#include "cli/fins/udp_socket.hpp"
#include "cli/fins/verb_support.hpp"
#include "fins/commands/configuration.hpp"
#include "fins/frame.hpp"

namespace fins::cli {

namespace {

constexpr std::size_t max_hosts = 1024;  // a /22: a sane sweep of one site's networks
constexpr unsigned min_prefix = 22;
// The source node of the requests: 254 as `fins probe` uses (a node no PLC of a /24
// converts to an IP address of its own).
constexpr std::uint8_t discover_source_node = 254;

struct DiscoverArgs {
    std::string hosts;
    unsigned parallel = 64;
};

std::optional<std::uint32_t> ipv4(std::string_view text) {
    boost::system::error_code ec;
    const auto a = boost::asio::ip::make_address_v4(std::string(text), ec);
    if (ec) return std::nullopt;
    return a.to_uint();
}

std::string ipv4_text(std::uint32_t host) {
    return fmt::format("{}.{}.{}.{}", host >> 24, host >> 16 & 0xFF, host >> 8 & 0xFF, host & 0xFF);
}

// The hosts of RANGE in order, or why not.
tl::expected<std::vector<std::uint32_t>, std::string> parse_hosts(const std::string& range) {
    std::vector<std::uint32_t> hosts;
    const auto add = [&](std::uint64_t first, std::uint64_t last) -> bool {
        if (last < first || last - first + 1 + hosts.size() > max_hosts) return false;
        for (auto h = first; h <= last; ++h)
            hosts.push_back(static_cast<std::uint32_t>(h));
        return true;
    };
    const auto too_many = fmt::format("--hosts '{}': more than {} hosts", range, max_hosts);
    std::string_view rest = range;
    // Bounded: each turn consumes one comma-separated item.
    while (!rest.empty()) {
        const auto comma = rest.find(',');
        const auto item = rest.substr(0, comma);
        rest = comma == std::string_view::npos ? std::string_view{} : rest.substr(comma + 1);
        const auto bad = tl::unexpected(fmt::format(
            "--hosts: '{}' is not A.B.C.D, A.B.C.D-E, A.B.C.D-W.X.Y.Z or A.B.C.D/N", item));
        if (const auto slash = item.find('/'); slash != std::string_view::npos) {
            const auto base = ipv4(item.substr(0, slash));
            const auto bits = parse_number(std::string(item.substr(slash + 1)), 32);
            if (!base || !bits) return bad;
            if (*bits < min_prefix)
                return tl::unexpected(
                    fmt::format("--hosts '{}': /{} is more than {} hosts (/{} "
                                "at most)",
                                item, *bits, max_hosts, min_prefix));
            const std::uint64_t size = std::uint64_t{1} << (32 - *bits);
            const std::uint64_t network = *base & ~(size - 1);
            const bool ends = size >= 4;  // network and broadcast addresses are no hosts
            if (!add(network + (ends ? 1 : 0), network + size - 1 - (ends ? 1 : 0)))
                return tl::unexpected(too_many);
        } else if (const auto dash = item.find('-'); dash != std::string_view::npos) {
            const auto first = ipv4(item.substr(0, dash));
            auto tail = item.substr(dash + 1);
            std::optional<std::uint32_t> last;
            if (tail.find('.') == std::string_view::npos) {
                const auto octet = parse_number(std::string(tail), 255);
                if (first && octet) last = (*first & 0xFFFFFF00U) | *octet;
            } else {
                last = ipv4(tail);
            }
            if (!first || !last) return bad;
            if (*last < *first)
                return tl::unexpected(fmt::format("--hosts '{}': the range runs backwards", item));
            if (!add(*first, *last)) return tl::unexpected(too_many);
        } else {
            const auto one = ipv4(item);
            if (!one) return bad;
            if (!add(*one, *one)) return tl::unexpected(too_many);
        }
    }
    if (hosts.empty()) return tl::unexpected(std::string("--hosts: no host given"));
    return hosts;
}

struct Target {
    std::uint32_t host = 0;
    unsigned attempts = 0;
    std::chrono::steady_clock::time_point deadline;
    std::optional<FoundNode> found;
    std::string version;
};

class Sweep {
  public:
    Sweep(const GlobalOptions& g, std::vector<Target>& targets, unsigned parallel)
        : g_(g), targets_(targets), parallel_(parallel) {
        error_ = socket_.open_v4();
        wait_ = std::chrono::milliseconds(static_cast<long>(g.timeout_seconds * 1000.0 + 0.5));
        if (auto s = parse_node_address(g.source); s && !g.source.empty()) source_ = *s;
    }
    Sweep(const Sweep&) = delete;
    Sweep& operator=(const Sweep&) = delete;

    // Why the socket could not be opened, if it could not.
    [[nodiscard]] std::error_code error() const { return error_; }

    // Bounded: every target is sent at most retries + 1 times, each attempt ends at its
    // deadline, and a target leaves `in_flight_` on its answer or its last deadline.
    void run() {
        std::size_t next = 0;
        while (next < targets_.size() || !in_flight_.empty()) {
            while (in_flight_.size() < parallel_ && next < targets_.size()) {
                if (send(next)) in_flight_.push_back(next);
                ++next;
            }
            if (in_flight_.empty()) continue;
            auto earliest = targets_[in_flight_.front()].deadline;
            for (auto i : in_flight_)
                earliest = std::min(earliest, targets_[i].deadline);
            const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(
                earliest - std::chrono::steady_clock::now());
            std::array<std::uint8_t, max_frame_size> in{};
            UdpSocket::Endpoint from;
            // An error here is a host's ICMP answer (nothing listens): it does not answer.
            if (auto n = socket_.receive(in, left + std::chrono::milliseconds(1), &from);
                n && *n > 0)
                take(Bytes(in.data(), *n), from);
            receive();
            expire();
        }
    }

  private:
    bool send(std::size_t index) {
        Target& t = targets_[index];
        Header h;
        h.destination = NodeAddress{0, 0, 0};
        h.source = source_;
        h.service_id = static_cast<std::uint8_t>(index);
        const std::array<std::uint8_t, 1> section{
            static_cast<std::uint8_t>(CpuUnitDataSection::model_and_area)};
        std::array<std::uint8_t, 64> frame{};
        const auto size = encode_request(h, CpuUnitDataRead::code, section, frame);
        ++t.attempts;
        t.deadline = std::chrono::steady_clock::now() + wait_;
        // A host the system cannot send to (no route) is one that does not answer.
        return size && !socket_.send_to(t.host, g_.port, {frame.data(), *size});
    }

    void receive() {
        // Bounded: the socket is drained without waiting, at most max_hosts datagrams.
        for (std::size_t n = 0; n < max_hosts; ++n) {
            std::array<std::uint8_t, max_frame_size> in{};
            UdpSocket::Endpoint from;
            const auto got = socket_.try_receive(in, from);
            if (!got) return;
            take(Bytes(in.data(), *got), from);
        }
    }

    void take(Bytes datagram, const UdpSocket::Endpoint& from) {
        auto r = decode_response(datagram);
        if (!r || r->command != CpuUnitDataRead::code || !from.address().is_v4()) return;
        const auto host = from.address().to_v4().to_uint();
        const auto it = std::find_if(in_flight_.begin(), in_flight_.end(), [&](auto i) {
            return targets_[i].host == host && static_cast<std::uint8_t>(i) == r->header.service_id;
        });
        if (it == in_flight_.end()) return;
        Target& t = targets_[*it];
        t.found = FoundNode{r->header.source, {}, {}};
        t.found->address.unit = 0;
        if (r->code.ok())
            if (auto data =
                    CpuUnitDataRead{CpuUnitDataSection::model_and_area}.decode_response(r->data)) {
                t.found->model = data->model;
                t.version = data->system_version;
            }
        in_flight_.erase(it);
    }

    void expire() {
        const auto now = std::chrono::steady_clock::now();
        for (auto it = in_flight_.begin(); it != in_flight_.end();) {
            Target& t = targets_[*it];
            if (now < t.deadline) {
                ++it;
            } else if (t.attempts <= g_.retries && send(*it)) {
                ++it;
            } else {
                it = in_flight_.erase(it);
            }
        }
    }

    const GlobalOptions& g_;
    std::vector<Target>& targets_;
    unsigned parallel_;
    UdpSocket socket_;
    std::error_code error_;
    std::chrono::milliseconds wait_{};
    NodeAddress source_{0, discover_source_node, 0};
    std::deque<std::size_t> in_flight_;
};

int run_discover(const GlobalOptions& g, const DiscoverArgs& a, Output& out) {
    if (g.tcp || !g.serial.empty())
        return out.usage("discover sweeps FINS/UDP: drop --tcp / --serial");
    auto hosts = parse_hosts(a.hosts);
    if (!hosts) return out.usage(hosts.error());
    std::vector<Target> targets;
    targets.reserve(hosts->size());
    for (auto h : *hosts)
        targets.push_back(Target{h, 0, {}, std::nullopt, {}});
    Sweep sweep(g, targets, a.parallel);
    if (sweep.error()) return out.failure(sweep.error(), "discover");
    sweep.run();

    nlohmann::json nodes = nlohmann::json::array();
    std::string text;
    std::size_t answered = 0;
    for (const auto& t : targets) {
        if (!t.found) continue;
        ++answered;
        const auto host = ipv4_text(t.host);
        nodes.push_back({{"host", host},
                         {"node", node_text(t.found->address)},
                         {"model", t.found->model},
                         {"version", t.version}});
        text += fmt::format("{:<15}  {:<9}  {:<20}  {}\n", host, node_text(t.found->address),
                            t.found->model.empty() ? "-" : t.found->model,
                            t.version.empty() ? "-" : t.version);
    }
    const auto context = fmt::format("discover {} (UDP port {})", a.hosts, g.port);
    if (answered == 0) {
        // Nobody answered is a result a script reads like any other (an empty list),
        // with exit 3 and the reason on stderr.
        if (!out.json()) return out.failure(make_error_code(ClientError::timeout), context);
        out.print({{"port", g.port}, {"hosts", targets.size()}, {"nodes", nodes}}, text);
        fmt::print(stderr, "fins: {}: no node answered\n", context);
        return exit_transport;
    }
    text += fmt::format("{} of {} answered (UDP port {})\n", answered,
                        plural(targets.size(), "host"), g.port);
    out.print({{"port", g.port}, {"hosts", targets.size()}, {"nodes", nodes}}, text);
    return exit_ok;
}

}  // namespace

void add_discover_verbs(CLI::App& app, const GlobalOptions& g, int& exit_code) {
    auto a = std::make_shared<DiscoverArgs>();
    auto* c = verb(app, "discover", "List the FINS nodes answering on an IPv4 range (05 01)", g,
                   exit_code, a, &run_discover);
    c->add_option("--hosts", a->hosts,
                  "A.B.C.D, A.B.C.D-E, A.B.C.D-W.X.Y.Z or A.B.C.D/N (N 22-32), comma-separated")
        ->required();
    c->add_option("--parallel", a->parallel, "Requests in flight at once")
        ->capture_default_str()
        ->check(CLI::Range(1, 256));
}

}  // namespace fins::cli
