// End codes (W342 5-1-3) and the library's other error categories.
//
// The end-code table is generated from fins/end_codes.def, the single source of truth,
// so the enum in error.hpp, this lookup table and the messages cannot drift apart.
#include <algorithm>
#include <array>
#include <string>

#include <fmt/format.h>

#include "fins/error.hpp"

namespace fins {
namespace {

constexpr std::array end_codes{
#define X(id_, code_, name_, cause_) EndCodeInfo{EndCode::id_, #id_, name_, cause_},
#include "fins/end_codes.def"
#undef X
};

// find_end_code() relies on this order.
constexpr bool ascending() {
    for (std::size_t i = 1; i < end_codes.size(); ++i)
        if (end_codes[i - 1].code >= end_codes[i].code) return false;
    return true;
}
static_assert(ascending(), "end_codes.def must be sorted by code without duplicates");

class EndCodeCategory final : public std::error_category {
  public:
    const char* name() const noexcept override { return "fins.end_code"; }
    std::string message(int value) const override {
        // Values outside 16 bits cannot be end codes; describe them as unknown.
        if (value < 0 || value > 0xFFFF) return fmt::format("unknown end code {}", value);
        const auto code = static_cast<std::uint16_t>(value);
        if (const auto* info = find_end_code(code))
            return fmt::format("{} (0x{:04X}): {}", info->name, code, info->message);
        return fmt::format("unknown end code 0x{:04X}", code);
    }
};

class ClientCategory final : public std::error_category {
  public:
    const char* name() const noexcept override { return "fins.client"; }
    std::string message(int value) const override {
        switch (static_cast<ClientError>(value)) {
            case ClientError::timeout:
                return "no response within the timeout";
            case ClientError::malformed_response:
                return "malformed response";
            case ClientError::unexpected_response:
                return "response does not match the request";
            case ClientError::connection_closed:
                return "connection closed";
            case ClientError::too_many_in_flight:
                return "all 256 service IDs are in use";
            case ClientError::request_too_long:
                return "request longer than the 2,012-byte frame limit";
            case ClientError::not_connected:
                return "not connected";
            case ClientError::canceled:
                return "request canceled";
            case ClientError::handshake_failed:
                return "FINS/TCP node address exchange failed";
            case ClientError::invalid_argument:
                return "invalid argument";
            case ClientError::called_from_callback:
                return "synchronous client call from inside a completion callback (use "
                       "async_send there)";
        }
        return fmt::format("unknown client error {}", value);
    }
};

// Texts of frames 3.3 (W421 7-4).
class TcpCategory final : public std::error_category {
  public:
    const char* name() const noexcept override { return "fins.tcp"; }
    std::string message(int value) const override {
        switch (static_cast<TcpError>(value)) {
            case TcpError::not_fins_header:
                return "the header is not \"FINS\"";
            case TcpError::data_length_too_long:
                return "the data length is too long";
            case TcpError::command_not_supported:
                return "the command is not supported";
            case TcpError::all_connections_in_use:
                return "all connections are in use";
            case TcpError::node_already_connected:
                return "the specified node is already connected";
            case TcpError::protected_node:
                return "attempt to access a protected node from an unspecified IP address";
            case TcpError::client_node_out_of_range:
                return "the client FINS node address is out of range";
            case TcpError::same_node_as_server:
                return "the client and the server use the same FINS node address";
            case TcpError::no_node_available:
                return "all node addresses available for allocation are in use";
        }
        return fmt::format("unknown FINS/TCP error 0x{:02X}", value);
    }
};

class AddressCategory final : public std::error_category {
  public:
    const char* name() const noexcept override { return "fins.address"; }
    std::string message(int value) const override {
        switch (static_cast<AddressError>(value)) {
            case AddressError::empty:
                return "empty address";
            case AddressError::unknown_area:
                return "unknown memory area";
            case AddressError::bad_number:
                return "bad number in address";
            case AddressError::word_out_of_range:
                return "word number out of range for the area";
            case AddressError::bit_out_of_range:
                return "bit number out of range (0-15)";
            case AddressError::bank_out_of_range:
                return "EM bank out of range (0-18 hex)";
            case AddressError::bit_not_allowed:
                return "the area has no bit access";
            case AddressError::bit_required:
                return "the area has only bit access";
            case AddressError::trailing_characters:
                return "unexpected characters in address";
        }
        return fmt::format("unknown address error {}", value);
    }
};

}  // namespace

std::span<const EndCodeInfo> end_code_table() noexcept {
    return end_codes;
}

const EndCodeInfo* find_end_code(std::uint16_t code) noexcept {
    const auto it = std::lower_bound(end_codes.begin(), end_codes.end(), code,
                                     [](const EndCodeInfo& info, std::uint16_t c) {
                                         return static_cast<std::uint16_t>(info.code) < c;
                                     });
    if (it == end_codes.end() || static_cast<std::uint16_t>(it->code) != code) return nullptr;
    return &*it;
}

const std::error_category& end_code_category() noexcept {
    static const EndCodeCategory category;
    return category;
}
std::error_code make_error_code(EndCode e) noexcept {
    return {static_cast<int>(e), end_code_category()};
}

const std::error_category& client_category() noexcept {
    static const ClientCategory category;
    return category;
}
std::error_code make_error_code(ClientError e) noexcept {
    return {static_cast<int>(e), client_category()};
}

const std::error_category& tcp_category() noexcept {
    static const TcpCategory category;
    return category;
}
std::error_code make_error_code(TcpError e) noexcept {
    return {static_cast<int>(e), tcp_category()};
}

const std::error_category& address_category() noexcept {
    static const AddressCategory category;
    return category;
}
std::error_code make_error_code(AddressError e) noexcept {
    return {static_cast<int>(e), address_category()};
}

std::string describe(std::error_code ec) {
    if (ec.category() != end_code_category()) return ec.message();
    const auto value = ec.value();
    if (value < 0 || value > 0xFFFF) return ec.message();
    const auto code = static_cast<std::uint16_t>(value);
    if (const auto* info = find_end_code(code)) return fmt::format("{:04X} {}", code, info->name);
    return fmt::format("{:04X} unknown end code", code);
}

}  // namespace fins
