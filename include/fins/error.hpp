// Errors: FINS end codes (W342 5-1-3) and the library's local failures, all as
// std::error_code so callers handle every failure the same way.
//
// - EndCode: the 14-bit main/sub code a FINS unit answers (flag bits masked off).
// - ResponseCode: the raw 16-bit end-code word with its flag bits (W342 5-1-3 note):
//   bit 15 network relay error, bit 7 fatal CPU error, bit 6 non-fatal CPU error.
//   0x0040 is still success (battery error on an otherwise normal completion).
// - ClientError: failures seen locally by the client (timeout, malformed answer ...).
// - TcpError: the FINS/TCP envelope error codes (W421 7-4, frames 3.3).
// - AddressError: bad PLC address strings.
#pragma once

#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <system_error>

#include <tl/expected.hpp>

namespace fins {

template <class T>
using Result = tl::expected<T, std::error_code>;
using Unexpected = tl::unexpected<std::error_code>;

enum class EndCode : std::uint16_t {
#define X(name, code, text, cause) name = code,
#include "fins/end_codes.def"
#undef X
};

struct EndCodeInfo {
    EndCode code;
    std::string_view id;       // enumerator name, e.g. "address_range_error"
    std::string_view name;     // short manual name, e.g. "address range error"
    std::string_view message;  // probable cause from W342 5-1-3
};

// Every row of W342 5-1-3, ascending by code.
std::span<const EndCodeInfo> end_code_table() noexcept;
// nullptr for a code the manual does not list.
const EndCodeInfo* find_end_code(std::uint16_t code) noexcept;

const std::error_category& end_code_category() noexcept;
std::error_code make_error_code(EndCode e) noexcept;

// Raw end-code word as received, with the flag bits.
class ResponseCode {
  public:
    constexpr ResponseCode() = default;
    constexpr explicit ResponseCode(std::uint16_t raw) noexcept : raw_(raw) {}

    [[nodiscard]] constexpr std::uint16_t raw() const noexcept { return raw_; }
    // Main code & 0x7F, sub code & 0x3F.
    [[nodiscard]] constexpr EndCode end_code() const noexcept {
        return static_cast<EndCode>(raw_ & 0x7F3F);
    }
    [[nodiscard]] constexpr bool ok() const noexcept { return (raw_ & 0x7F3F) == 0; }
    [[nodiscard]] constexpr bool relay_error() const noexcept { return (raw_ & 0x8000) != 0; }
    [[nodiscard]] constexpr bool fatal_cpu_error() const noexcept { return (raw_ & 0x0080) != 0; }
    [[nodiscard]] constexpr bool non_fatal_cpu_error() const noexcept {
        return (raw_ & 0x0040) != 0;
    }
    friend constexpr bool operator==(ResponseCode, ResponseCode) = default;

    static constexpr std::uint16_t relay_error_bit = 0x8000;
    static constexpr std::uint16_t fatal_cpu_error_bit = 0x0080;
    static constexpr std::uint16_t non_fatal_cpu_error_bit = 0x0040;

  private:
    std::uint16_t raw_ = 0;
};

// Where a relayed command failed: the word that follows the end code when bit 15 is on.
struct RelayErrorSource {
    std::uint8_t network = 0;
    std::uint8_t node = 0;
    friend constexpr bool operator==(const RelayErrorSource&, const RelayErrorSource&) = default;
};

enum class ClientError : int {
    timeout = 1,           // no response within the timeout after every retry
    malformed_response,    // response too short, wrong length for the request, bad header
    unexpected_response,   // command code or addresses do not match the request
    connection_closed,     // transport closed or failed while the request was in flight
    too_many_in_flight,    // all 256 service IDs are in use
    request_too_long,      // encoded command longer than the 2,012-byte frame limit
    not_connected,         // transport not open
    canceled,              // client destroyed or request canceled
    handshake_failed,      // FINS/TCP node-address exchange did not complete
    invalid_argument,      // caller passed a value the command cannot carry
    called_from_callback,  // a synchronous Client call made inside a completion callback
};
const std::error_category& client_category() noexcept;
std::error_code make_error_code(ClientError e) noexcept;

// FINS/TCP error-code field values (frames 3.3).
enum class TcpError : int {
    not_fins_header = 0x01,
    data_length_too_long = 0x02,
    command_not_supported = 0x03,
    all_connections_in_use = 0x20,
    node_already_connected = 0x21,
    protected_node = 0x22,
    client_node_out_of_range = 0x23,
    same_node_as_server = 0x24,
    no_node_available = 0x25,
};
const std::error_category& tcp_category() noexcept;
std::error_code make_error_code(TcpError e) noexcept;

enum class AddressError : int {
    empty = 1,
    unknown_area,
    bad_number,
    word_out_of_range,
    bit_out_of_range,
    bank_out_of_range,
    bit_not_allowed,  // area has no bit access (IR, DR)
    bit_required,     // area has only bit access (TK)
    trailing_characters,
};
const std::error_category& address_category() noexcept;
std::error_code make_error_code(AddressError e) noexcept;

// "1103 address range error" for end codes, ec.message() for everything else: text
// for logs and the CLI.
std::string describe(std::error_code ec);

}  // namespace fins

template <>
struct std::is_error_code_enum<fins::EndCode> : std::true_type {};
template <>
struct std::is_error_code_enum<fins::ClientError> : std::true_type {};
template <>
struct std::is_error_code_enum<fins::TcpError> : std::true_type {};
template <>
struct std::is_error_code_enum<fins::AddressError> : std::true_type {};
