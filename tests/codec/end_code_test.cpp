// End-code table (W342 5-1-3), ResponseCode flag bits and the error categories.
#include <set>
#include <string>

#include <gtest/gtest.h>

#include "fins/error.hpp"

namespace fins {
namespace {

TEST(EndCode, TableWalkEveryRow) {
    const auto table = end_code_table();
    ASSERT_GE(table.size(), 80u);
    std::set<std::string_view> ids;
    for (std::size_t i = 0; i < table.size(); ++i) {
        const auto& row = table[i];
        const auto code = static_cast<std::uint16_t>(row.code);
        SCOPED_TRACE(row.id);
        EXPECT_FALSE(row.id.empty());
        EXPECT_FALSE(row.name.empty());
        EXPECT_FALSE(row.message.empty());
        EXPECT_TRUE(ids.insert(row.id).second) << "duplicate id";
        if (i > 0) {
            EXPECT_LT(static_cast<std::uint16_t>(table[i - 1].code), code);
        }
        // Flag bits (15, 7, 6) are never part of a listed code.
        EXPECT_EQ(code & 0x80C0, 0);
        EXPECT_EQ(find_end_code(code), &row);
        const auto ec = make_error_code(row.code);
        EXPECT_EQ(&ec.category(), &end_code_category());
        EXPECT_FALSE(ec.message().empty());
        EXPECT_NE(ec.message().find(std::string(row.name)), std::string::npos);
    }
}

TEST(EndCode, MessageAndDescribe) {
    const std::error_code ec = EndCode::address_range_error;
    EXPECT_STREQ(ec.category().name(), "fins.end_code");
    EXPECT_EQ(ec.message(),
              "address range error (0x1103): the start address is beyond the accessible area");
    EXPECT_EQ(describe(ec), "1103 address range error");
    EXPECT_EQ(describe(make_error_code(EndCode::command_too_short)), "1002 command too short");
    EXPECT_EQ(describe(make_error_code(ClientError::timeout)), "no response within the timeout");
}

TEST(EndCode, UnknownCode) {
    EXPECT_EQ(find_end_code(0x1107), nullptr);
    EXPECT_EQ(find_end_code(0xFFFF), nullptr);
    const std::error_code ec(0x1107, end_code_category());
    EXPECT_EQ(ec.message(), "unknown end code 0x1107");
    EXPECT_EQ(describe(ec), "1107 unknown end code");
    EXPECT_EQ(std::error_code(-1, end_code_category()).message(), "unknown end code -1");
}

TEST(EndCode, FindFirstAndLast) {
    EXPECT_EQ(find_end_code(0x0000)->code, EndCode::normal_completion);
    EXPECT_EQ(find_end_code(0x4001)->code, EndCode::service_aborted);
    EXPECT_EQ(find_end_code(0x0000), &end_code_table().front());
    EXPECT_EQ(find_end_code(0x4001), &end_code_table().back());
}

TEST(ResponseCode, NonFatalFlagIsStillSuccess) {
    // W342 5-1-3: a battery error on a normal completion gives 0040.
    const ResponseCode rc(0x0040);
    EXPECT_TRUE(rc.ok());
    EXPECT_TRUE(rc.non_fatal_cpu_error());
    EXPECT_FALSE(rc.fatal_cpu_error());
    EXPECT_FALSE(rc.relay_error());
    EXPECT_EQ(rc.end_code(), EndCode::normal_completion);
}

TEST(ResponseCode, FlagsMaskedOff) {
    const ResponseCode relay(0x8000 | 0x0101);
    EXPECT_FALSE(relay.ok());
    EXPECT_TRUE(relay.relay_error());
    EXPECT_EQ(relay.end_code(), EndCode::local_node_not_in_network);

    const ResponseCode fatal(0x1103 | 0x0080);
    EXPECT_TRUE(fatal.fatal_cpu_error());
    EXPECT_EQ(fatal.end_code(), EndCode::address_range_error);

    const ResponseCode all(0xFFFF);
    EXPECT_EQ(static_cast<std::uint16_t>(all.end_code()), 0x7F3F);
    EXPECT_TRUE(all.relay_error() && all.fatal_cpu_error() && all.non_fatal_cpu_error());
}

TEST(ErrorCategories, NamesAndMessages) {
    EXPECT_STREQ(client_category().name(), "fins.client");
    EXPECT_STREQ(tcp_category().name(), "fins.tcp");
    EXPECT_STREQ(address_category().name(), "fins.address");
    for (int e = 1; e <= static_cast<int>(ClientError::invalid_argument); ++e) {
        const auto msg = make_error_code(static_cast<ClientError>(e)).message();
        EXPECT_FALSE(msg.empty());
        EXPECT_EQ(msg.find("unknown"), std::string::npos) << e;
    }
    for (int e : {0x01, 0x02, 0x03, 0x20, 0x21, 0x22, 0x23, 0x24, 0x25}) {
        const auto msg = make_error_code(static_cast<TcpError>(e)).message();
        EXPECT_EQ(msg.find("unknown"), std::string::npos) << e;
    }
    EXPECT_EQ(make_error_code(TcpError::not_fins_header).message(), "the header is not \"FINS\"");
    EXPECT_EQ(std::error_code(0x7F, tcp_category()).message(), "unknown FINS/TCP error 0x7F");
    for (int e = 1; e <= static_cast<int>(AddressError::trailing_characters); ++e) {
        const auto msg = make_error_code(static_cast<AddressError>(e)).message();
        EXPECT_EQ(msg.find("unknown address error"), std::string::npos) << e;
    }
    // Each enum converts implicitly, and categories keep errors apart.
    const std::error_code a = ClientError::timeout;
    const std::error_code b = AddressError::empty;
    EXPECT_NE(a, b);
    EXPECT_EQ(a.value(), b.value());
}

}  // namespace
}  // namespace fins
