// Relays in a running plant, end to end (docs/networks.md "Routing"): the finsd process
// runs examples/three-networks.toml (its units on free ports instead of 9600) with its
// HTTP front. A client on network 1, at router-a's unit 1.1, writes and reads line-3
// (node 3.5) two networks away through router-a and router-b, over FINS/UDP and
// FINS/TCP, with raw sockets so every header byte of the answer is checked (W342 3-3:
// the answer goes from 3.5 back to the client's network and node, with its SID). A
// network in no routing table answers 8501 with the relay word of the router that
// found it (W342 5-1-3), and /api/status "relays" and /metrics count what each router
// took and refused.
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <regex>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "integration/support/finsd_process.hpp"
#include "integration/support/free_port.hpp"
#include "integration/support/raw_socket.hpp"
#include "web/web_server.hpp"

namespace fins::test {
namespace {

using Json = nlohmann::json;

constexpr std::uint8_t client_node = 77;  // node 1.77: no unit of the plant has it

// The example's text with its fixed `port = 9600` lines taken out (the units then take
// --port 0: free ports), and an [http] table on `http_port`.
std::string example_on_free_ports(std::uint16_t http_port) {
    std::ifstream in(std::filesystem::path(FINS_SOURCE_DIR) / "examples" / "three-networks.toml");
    std::ostringstream out;
    std::string line;
    while (std::getline(in, line))
        if (!std::regex_match(line, std::regex(R"(\s*port\s*=\s*9600\s*)"))) out << line << '\n';
    out << "\n[http]\nlisten = \"127.0.0.1:" << http_port << "\"\n";
    return out.str();
}

// A FINS command frame from `source` to `destination` (GCT 02, W342 3-3-3).
std::vector<std::uint8_t> command(NodeAddress destination, NodeAddress source, std::uint8_t sid,
                                  CommandCode code, const std::vector<std::uint8_t>& params) {
    Header h;
    h.destination = destination;
    h.source = source;
    h.service_id = sid;
    std::vector<std::uint8_t> out(max_frame_size);
    out.resize(encode_request(h, code, params, out).value_or(0));
    return out;
}

// 01 02 MEMORY AREA WRITE of `words` at D`at`; 01 01 MEMORY AREA READ of `count` words.
std::vector<std::uint8_t> write_params(std::uint16_t at, const std::vector<std::uint16_t>& words) {
    std::vector<std::uint8_t> p{
        0x82, static_cast<std::uint8_t>(at >> 8),     static_cast<std::uint8_t>(at & 0xFF), 0x00,
        0x00, static_cast<std::uint8_t>(words.size())};
    for (auto w : words) {
        p.push_back(static_cast<std::uint8_t>(w >> 8));
        p.push_back(static_cast<std::uint8_t>(w & 0xFF));
    }
    return p;
}
std::vector<std::uint8_t> read_params(std::uint16_t at, std::uint8_t count) {
    return {
        0x82, static_cast<std::uint8_t>(at >> 8), static_cast<std::uint8_t>(at & 0xFF), 0x00, 0x00,
        count};
}

// The answer's header bytes other than GCT (how far it counted down is the routers'
// business, pinned in plant_test.cpp), command code and end code.
struct Answer {
    std::uint8_t icf = 0, rsv = 0xFF;
    NodeAddress destination, source;
    std::uint8_t sid = 0;
    std::uint8_t mrc = 0, src = 0;
    std::uint16_t end_code = 0xFFFF;
    std::vector<std::uint8_t> rest;  // after the end code (a relay word, read data)
};
Answer parse(const std::vector<std::uint8_t>& f, std::size_t at = 0) {
    Answer a;
    if (f.size() < at + 14) return a;
    a.icf = f[at];
    a.rsv = f[at + 1];
    a.destination = {f[at + 3], f[at + 4], f[at + 5]};
    a.source = {f[at + 6], f[at + 7], f[at + 8]};
    a.sid = f[at + 9];
    a.mrc = f[at + 10];
    a.src = f[at + 11];
    a.end_code = static_cast<std::uint16_t>(f[at + 12] << 8 | f[at + 13]);
    a.rest.assign(f.begin() + static_cast<std::ptrdiff_t>(at + 14), f.end());
    return a;
}

// A FINS/UDP socket of node 1.77: bound to 127.0.1.77, as the automatic node-address
// method (W596 2-3) places node 77 of network 1.
class UdpNode {
  public:
    explicit UdpNode(std::uint16_t server_port) : fd_(::socket(AF_INET, SOCK_DGRAM, 0)) {
        sockaddr_in a{};
        a.sin_family = AF_INET;
        a.sin_addr.s_addr = htonl(0x7F00014D);  // 127.0.1.77
        EXPECT_EQ(::bind(fd_, reinterpret_cast<sockaddr*>(&a), sizeof a), 0);
        set_receive_timeout(fd_, 5);
        server_.sin_family = AF_INET;
        server_.sin_port = htons(server_port);
        server_.sin_addr.s_addr = htonl(0x7F000101);  // router-a's unit, 127.0.1.1
    }
    ~UdpNode() { ::close(fd_); }
    UdpNode(const UdpNode&) = delete;
    UdpNode& operator=(const UdpNode&) = delete;
    // Sends `frame` and returns the datagram that came back (empty: none within 5 s).
    std::vector<std::uint8_t> exchange(const std::vector<std::uint8_t>& frame) {
        ::sendto(fd_, frame.data(), frame.size(), 0, reinterpret_cast<const sockaddr*>(&server_),
                 sizeof server_);
        std::vector<std::uint8_t> in(max_frame_size);
        const auto n = ::recv(fd_, in.data(), in.size(), 0);
        in.resize(n > 0 ? static_cast<std::size_t>(n) : 0);
        return in;
    }

  private:
    int fd_;
    sockaddr_in server_{};
};

class PlantRelayRun : public ::testing::Test {
  protected:
    void SetUp() override {
        http_port_ = free_tcp_port();
        finsd_ = std::make_unique<Finsd>(std::vector<std::string>{
            "--config", dir_.write("plant.toml", example_on_free_ports(http_port_))});
        ASSERT_TRUE(finsd_->started()) << finsd_->result().err;
    }
    // router-a's unit on network 1: "listening" names the first unit's port.
    [[nodiscard]] std::uint16_t fins_port() const { return finsd_->port(); }
    Json get(const std::string& target) {
        HttpClient http(http_port_);
        return body_json(http.request(http::verb::get, target));
    }
    // fins_relays_total and fins_relay_errors_total{end_code="CODE"} from /metrics.
    long metric(const std::string& name) {
        HttpClient http(http_port_);
        const auto text = http.request(http::verb::get, "/metrics").body();
        const auto at = text.find("\n" + name + " ");
        return at == std::string::npos ? -1 : std::stol(text.substr(at + name.size() + 2));
    }

    ScratchDir dir_{"plant-relay"};
    std::uint16_t http_port_ = 0;
    std::unique_ptr<Finsd> finsd_;
};

TEST_F(PlantRelayRun, UdpWriteAndReadReachLine3TwoNetworksAwayAndComeBackToTheClient) {
    UdpNode client(fins_port());
    const NodeAddress line_3{3, 5, 0};
    // SNA 01: the client names its network.
    const auto wrote = parse(client.exchange(command(
        line_3, {1, client_node, 0}, 0x41, {0x01, 0x02}, write_params(300, {0xCAFE, 0x0042}))));
    EXPECT_EQ(wrote.icf, 0xC0);  // a response, to a command that asked for one
    EXPECT_EQ(wrote.rsv, 0x00);
    EXPECT_EQ(wrote.destination, (NodeAddress{1, client_node, 0}));
    EXPECT_EQ(wrote.source, line_3);
    EXPECT_EQ(wrote.sid, 0x41);
    EXPECT_EQ(wrote.mrc, 0x01);
    EXPECT_EQ(wrote.src, 0x02);
    EXPECT_EQ(wrote.end_code, 0x0000);
    // SNA 00 ("this network"): router-a makes it network 1, so the answer still finds
    // its way back (W342 3-3-3).
    const auto read = parse(client.exchange(
        command(line_3, {0, client_node, 0}, 0x42, {0x01, 0x01}, read_params(300, 2))));
    EXPECT_EQ(read.destination, (NodeAddress{1, client_node, 0}));
    EXPECT_EQ(read.source, line_3);
    EXPECT_EQ(read.sid, 0x42);
    EXPECT_EQ(read.end_code, 0x0000);
    EXPECT_EQ(read.rest, (std::vector<std::uint8_t>{0xCA, 0xFE, 0x00, 0x42}));
    // The words are line-3's: asked of it directly on network 3 (its own port).
    const auto plcs = get("/api/plcs");
    std::uint16_t line_port = 0;
    for (const auto& p : plcs["plcs"])
        if (p.value("name", "") == "line-3") line_port = p.value("udp_port", std::uint16_t{0});
    ASSERT_NE(line_port, 0) << plcs.dump();
    ClientOptions o;
    o.host = "127.0.3.5";
    o.port = line_port;
    o.destination = line_3;
    o.timeout = std::chrono::milliseconds(3000);
    auto direct = Client::connect(o);
    ASSERT_TRUE(direct) << direct.error().message();
    EXPECT_EQ(words_of(**direct, "D300", 2), (std::vector<std::uint16_t>{0xCAFE, 0x0042}));
}

TEST_F(PlantRelayRun, TcpWriteAndReadReachLine3AndAnswerOnTheConnectionToItsNode) {
    asio::io_context io;
    RawTcp tcp(io, "127.0.1.1", fins_port());
    const auto hello = tcp.handshake(0);
    ASSERT_EQ(hello.size(), 24u);
    const std::uint8_t node = hello[19];  // the client node the server gave (W421 7-4)
    ASSERT_EQ(hello[23], 1);              // router-a's node on network 1
    const NodeAddress line_3{3, 5, 0};
    tcp.send(tcp_packet(TcpCommand::frame, command(line_3, {1, node, 0}, 0x51, {0x01, 0x02},
                                                   write_params(310, {0x1234, 0x5678, 0x9ABC}))));
    const auto wrote = parse(tcp.receive_packet(), tcp_header_size);
    EXPECT_EQ(wrote.destination, (NodeAddress{1, node, 0}));
    EXPECT_EQ(wrote.source, line_3);
    EXPECT_EQ(wrote.sid, 0x51);
    EXPECT_EQ(wrote.end_code, 0x0000);
    tcp.send(tcp_packet(TcpCommand::frame,
                        command(line_3, {0, node, 0}, 0x52, {0x01, 0x01}, read_params(310, 3))));
    const auto read = parse(tcp.receive_packet(), tcp_header_size);
    EXPECT_EQ(read.icf, 0xC0);
    EXPECT_EQ(read.destination, (NodeAddress{1, node, 0}));
    EXPECT_EQ(read.source, line_3);
    EXPECT_EQ(read.sid, 0x52);
    EXPECT_EQ(read.mrc, 0x01);
    EXPECT_EQ(read.src, 0x01);
    EXPECT_EQ(read.end_code, 0x0000);
    EXPECT_EQ(read.rest, (std::vector<std::uint8_t>{0x12, 0x34, 0x56, 0x78, 0x9A, 0xBC}));
}

TEST_F(PlantRelayRun, AnUnknownNetworkAnswers8501FromTheRouterThatFoundIt) {
    UdpNode client(fins_port());
    // Network 9 is in no table of router-a: router-a answers, naming its unit 1.1.
    const auto first = parse(client.exchange(
        command({9, 5, 0}, {1, client_node, 0}, 0x61, {0x01, 0x01}, read_params(0, 1))));
    EXPECT_EQ(first.icf, 0xC0);
    EXPECT_EQ(first.destination, (NodeAddress{1, client_node, 0}));
    EXPECT_EQ(first.source, (NodeAddress{9, 5, 0}));  // the command's destination
    EXPECT_EQ(first.sid, 0x61);
    EXPECT_EQ(first.mrc, 0x01);
    EXPECT_EQ(first.src, 0x01);
    EXPECT_EQ(first.end_code, 0x8501);  // relay error flag + 0501
    EXPECT_EQ(first.rest, (std::vector<std::uint8_t>{0x01, 0x01}));
    // 02 02 PARAMETER AREA WRITE to router-a (1.1): relay entry 2 says network 9 is
    // behind node 2.2 (router-b), which has no route to it and answers for itself.
    const auto table = parse(
        client.exchange(command({1, 1, 0}, {1, client_node, 0}, 0x62, {0x02, 0x02},
                                {0x80, 0x13, 0x00, 0x13, 0x00, 0x02, 0x09, 0x02, 0x00, 0x02})));
    ASSERT_EQ(table.end_code, 0x0000);
    const auto second = parse(client.exchange(
        command({9, 5, 0}, {1, client_node, 0}, 0x63, {0x01, 0x01}, read_params(0, 1))));
    EXPECT_EQ(second.destination, (NodeAddress{1, client_node, 0}));
    EXPECT_EQ(second.source, (NodeAddress{9, 5, 0}));
    EXPECT_EQ(second.sid, 0x63);
    EXPECT_EQ(second.end_code, 0x8501);
    EXPECT_EQ(second.rest, (std::vector<std::uint8_t>{0x02, 0x02}));  // router-b on network 2
}

TEST_F(PlantRelayRun, StatusAndMetricsCountWhatEachRouterTookAndRefused) {
    const auto relays = [&](const std::string& plc) {
        return get("/api/status?plc=" + plc)["relays"];
    };
    EXPECT_EQ(relays("router-a"), Json::parse(R"({"0000":0})"));
    EXPECT_EQ(relays("line-3"), Json::parse(R"({"0000":0})"));  // tables, nothing taken
    const long relays_before = metric("fins_relays_total");
    UdpNode client(fins_port());
    // Two commands to line-3: each router takes each once (the answers cross back).
    for (std::uint8_t sid = 1; sid <= 2; ++sid)
        ASSERT_EQ(parse(client.exchange(command({3, 5, 0}, {1, client_node, 0}, sid, {0x01, 0x01},
                                                read_params(0, 1))))
                      .end_code,
                  0x0000);
    // One to network 9: router-a refuses it.
    ASSERT_EQ(parse(client.exchange(command({9, 5, 0}, {1, client_node, 0}, 3, {0x01, 0x01},
                                            read_params(0, 1))))
                  .end_code,
              0x8501);
    EXPECT_EQ(relays("router-a"), Json::parse(R"({"0000":2,"0501":1})"));
    EXPECT_EQ(relays("router-b"), Json::parse(R"({"0000":2})"));
    EXPECT_EQ(relays("line-3"), Json::parse(R"({"0000":0})"));  // the answers are not counted
    // /api/plcs carries the same counts per CPU Unit.
    const auto plcs = get("/api/plcs");
    for (const auto& p : plcs["plcs"])
        if (p.value("name", "") == "router-a") {
            EXPECT_EQ(p["relays"], Json::parse(R"({"0000":2,"0501":1})"));
        }
    // The process's counters: five frames taken, one of them refused with 0501.
    EXPECT_EQ(metric("fins_relays_total") - relays_before, 5);
    EXPECT_EQ(metric("fins_relay_errors_total{end_code=\"0501\"}"), 1);
}

// A router has an Ethernet unit on each network: /api/plcs lists both (their ports and
// connections), and /api/status and /metrics count the FINS/TCP clients of both, not only
// of the first unit (they did: a client of router-a's network 2 unit was not seen).
TEST_F(PlantRelayRun, EveryEthernetUnitsClientsAreListedAndCounted) {
    Json router_a;
    const auto before = get("/api/plcs");
    for (const auto& p : before["plcs"])
        if (p.value("name", "") == "router-a") router_a = p;
    ASSERT_TRUE(router_a.is_object());
    const auto& units = router_a["ethernet_units"];
    ASSERT_EQ(units.size(), 2u) << router_a.dump();
    EXPECT_EQ(units[0]["network"], 1);
    EXPECT_EQ(units[0]["node"], 1);
    EXPECT_EQ(units[0]["udp_port"], router_a["udp_port"]);
    EXPECT_EQ(units[0]["tcp_port"], router_a["tcp_port"]);
    EXPECT_EQ(units[1]["network"], 2);
    EXPECT_EQ(units[1]["node"], 1);
    const auto second_port = units[1]["tcp_port"].get<std::uint16_t>();
    ASSERT_NE(second_port, 0);
    EXPECT_EQ(metric("fins_tcp_connections{state=\"established\"}"), 0);

    asio::io_context io;
    RawTcp first(io, "127.0.1.1", fins_port());
    ASSERT_EQ(first.handshake(0).size(), 24u);
    RawTcp second(io, "127.0.2.1", second_port);
    const auto hello = second.handshake(0);
    ASSERT_EQ(hello.size(), 24u);
    EXPECT_EQ(hello[23], 1) << "router-a's node on network 2";

    EXPECT_EQ(metric("fins_tcp_connections{state=\"established\"}"), 2);
    const auto connections = get("/api/status?plc=router-a")["connections"];
    ASSERT_EQ(connections.size(), 2u) << connections.dump();
    std::vector<int> networks;
    for (const auto& c : connections) {
        EXPECT_EQ(c["state"], "established");
        networks.push_back(c["network"].get<int>());
    }
    std::sort(networks.begin(), networks.end());
    EXPECT_EQ(networks, (std::vector<int>{1, 2}));
    const auto after = get("/api/plcs");
    for (const auto& p : after["plcs"])
        if (p.value("name", "") == "router-a") {
            EXPECT_EQ(p["tcp_connections"], 2);
            EXPECT_EQ(p["ethernet_units"][1]["tcp_connections"], 1);
        }
}

}  // namespace
}  // namespace fins::test
