// finsd bound to a wildcard address answers each FINS/UDP request from the address the
// request was sent to. A connected client socket (fins::Client's, most FINS libraries')
// takes datagrams only from the address it sent to: a reply from the address the route
// picks (127.0.0.1 for 127.0.0.3, or another address of a host with several) is dropped,
// and the client times out although finsd answered.
#include <arpa/inet.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <array>
#include <cstring>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "integration/support/finsd_process.hpp"
#include "integration/support/raw_socket.hpp"

namespace fins::test {
namespace {

// Sends MEMORY AREA READ of D0 from a socket connected to host:port and returns the
// address the answer came from ("" when none came within the receive timeout).
std::string answer_source(int family, const std::string& host, std::uint16_t port) {
    const int fd = ::socket(family, SOCK_DGRAM | SOCK_CLOEXEC, 0);
    EXPECT_GE(fd, 0);
    sockaddr_storage to{};
    socklen_t to_size = 0;
    if (family == AF_INET) {
        auto& a = reinterpret_cast<sockaddr_in&>(to);
        a.sin_family = AF_INET;
        a.sin_port = htons(port);
        EXPECT_EQ(::inet_pton(AF_INET, host.c_str(), &a.sin_addr), 1) << host;
        to_size = sizeof a;
    } else {
        auto& a = reinterpret_cast<sockaddr_in6&>(to);
        a.sin6_family = AF_INET6;
        a.sin6_port = htons(port);
        EXPECT_EQ(::inet_pton(AF_INET6, host.c_str(), &a.sin6_addr), 1) << host;
        to_size = sizeof a;
    }
    // connect(): the kernel then delivers only datagrams from host:port.
    EXPECT_EQ(::connect(fd, reinterpret_cast<sockaddr*>(&to), to_size), 0) << std::strerror(errno);
    set_receive_timeout(fd, 3);
    const auto frame = request_frame({0x01, 0x01}, {0x82, 0, 0, 0, 0, 1}, 0x5A);
    EXPECT_EQ(::send(fd, frame.data(), frame.size(), 0), static_cast<ssize_t>(frame.size()));
    std::array<std::uint8_t, 64> in{};
    sockaddr_storage from{};
    socklen_t from_size = sizeof from;
    const auto n =
        ::recvfrom(fd, in.data(), in.size(), 0, reinterpret_cast<sockaddr*>(&from), &from_size);
    ::close(fd);
    if (n < 14 || in[9] != 0x5A) return "";
    std::array<char, INET6_ADDRSTRLEN> text{};
    const void* a =
        from.ss_family == AF_INET
            ? static_cast<const void*>(&reinterpret_cast<sockaddr_in&>(from).sin_addr)
            : static_cast<const void*>(&reinterpret_cast<sockaddr_in6&>(from).sin6_addr);
    return ::inet_ntop(from.ss_family, a, text.data(), text.size()) ? text.data() : "?";
}

TEST(UdpReplySource, AWildcardFinsdAnswersFromTheAddressEachRequestWasSentTo) {
    Finsd finsd({"--bind", "0.0.0.0"});
    ASSERT_TRUE(finsd.started()) << finsd.result().err;
    for (const std::string host : {"127.0.0.1", "127.0.0.3", "127.1.2.3"})
        EXPECT_EQ(answer_source(AF_INET, host, finsd.port()), host);
}

TEST(UdpReplySource, ADualStackFinsdAnswersIpv4AndIpv6FromTheirOwnAddresses) {
    Finsd finsd({"--bind", "::"});
    ASSERT_TRUE(finsd.started()) << finsd.result().err;
    EXPECT_EQ(answer_source(AF_INET6, "::1", finsd.port()), "::1");
    // An IPv4 request to a dual-stack socket arrives as ::ffff:127.0.0.3.
    EXPECT_EQ(answer_source(AF_INET, "127.0.0.3", finsd.port()), "127.0.0.3");
}

}  // namespace
}  // namespace fins::test
