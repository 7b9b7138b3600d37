// The FINS/TCP connection table (W421 7-4 command 1 error codes) and the keep-alive
// options a session sets on its socket (README "FINS/TCP identity and limits").
#include <netinet/in.h>
#include <netinet/tcp.h>
#include <sys/socket.h>

#include <gtest/gtest.h>
#include <boost/asio/io_context.hpp>
#include <boost/asio/ip/tcp.hpp>

#include "server/sessions/tcp_node_table.hpp"
#include "server/sessions/tcp_session.hpp"
#include "transport/asio.hpp"

namespace fins::server {
namespace {

TcpSession* fake(std::uintptr_t n) {
    return reinterpret_cast<TcpSession*>(n * 64);
}

TEST(TcpNodeTable, W421_7_4_ErrorCodesOfCommandOne) {
    TcpNodeTable table(1, 2);
    EXPECT_EQ(table.claim(255, fake(1)).error(), TcpError::client_node_out_of_range);
    EXPECT_EQ(table.claim(1, fake(1)).error(), TcpError::same_node_as_server);
    EXPECT_EQ(table.claim(0, fake(1)).value(), 239);
    EXPECT_EQ(table.claim(239, fake(2)).error(), TcpError::node_already_connected);
    EXPECT_EQ(table.owner(239), fake(1));
    EXPECT_EQ(table.claim(20, fake(2)).value(), 20);
    EXPECT_EQ(table.claim(0, fake(3)).error(), TcpError::all_connections_in_use);
}

TEST(TcpNodeTable, ReleaseByAnotherSessionKeepsTheNode) {
    TcpNodeTable table(1, 16);
    ASSERT_EQ(table.claim(20, fake(1)).value(), 20);
    table.release(20, fake(2));  // a stale session must not free a node reused since
    EXPECT_EQ(table.owner(20), fake(1));
    table.release(20, fake(1));
    EXPECT_EQ(table.owner(20), nullptr);
    EXPECT_EQ(table.in_use(), 0u);
}

int option(int fd, int level, int name) {
    int value = -1;
    socklen_t size = sizeof value;
    ::getsockopt(fd, level, name, &value, &size);
    return value;
}

TEST(TcpKeepAlive, ProbesAfterTheIdleTimeThenThreeAThirdApart) {
    asio::io_context io;
    asio::ip::tcp::socket s(io);
    s.open(asio::ip::tcp::v4());
    ASSERT_FALSE(set_keepalive(s, std::chrono::seconds(30)));
    const int fd = s.native_handle();
    EXPECT_EQ(option(fd, SOL_SOCKET, SO_KEEPALIVE), 1);
    EXPECT_EQ(option(fd, IPPROTO_TCP, TCP_KEEPIDLE), 30);
    EXPECT_EQ(option(fd, IPPROTO_TCP, TCP_KEEPINTVL), 10);
    EXPECT_EQ(option(fd, IPPROTO_TCP, TCP_KEEPCNT), 3);
    ASSERT_FALSE(set_keepalive(s, std::chrono::seconds(2)));
    EXPECT_EQ(option(fd, IPPROTO_TCP, TCP_KEEPINTVL), 1);
    ASSERT_FALSE(set_keepalive(s, std::chrono::seconds(0)));
    EXPECT_EQ(option(fd, SOL_SOCKET, SO_KEEPALIVE), 0);
}

TEST(TcpKeepAlive, DefaultsAreSane) {
    const TcpLimits limits;
    EXPECT_EQ(limits.keepalive, std::chrono::seconds(60));
    EXPECT_EQ(limits.handshake_timeout, std::chrono::seconds(10));
    EXPECT_EQ(limits.frame_timeout, std::chrono::seconds(10));
    EXPECT_EQ(limits.idle_timeout, std::chrono::seconds(300));
    EXPECT_EQ(limits.max_pending, 16u);
}

}  // namespace
}  // namespace fins::server
