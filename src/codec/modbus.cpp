// Modbus-RTU / Modbus-ASCII framing (see fins/modbus.hpp).
#include "fins/modbus.hpp"
#include "codec/hex.hpp"

#include <array>

namespace fins::modbus {

namespace {

constexpr std::uint8_t cr = 0x0D;
constexpr std::uint8_t lf = 0x0A;
constexpr std::size_t crc_size = 2;

constexpr std::array<std::uint8_t, 16> digits{'0', '1', '2', '3', '4', '5', '6', '7',
                                              '8', '9', 'A', 'B', 'C', 'D', 'E', 'F'};

}  // namespace

std::uint16_t crc16(Bytes bytes) noexcept {
    std::uint16_t crc = 0xFFFF;
    for (auto b : bytes) {
        crc ^= b;
        for (int bit = 0; bit < 8; ++bit)
            crc = (crc & 1U) != 0 ? static_cast<std::uint16_t>((crc >> 1) ^ 0xA001U)
                                  : static_cast<std::uint16_t>(crc >> 1);
    }
    return crc;
}

std::uint8_t lrc(Bytes bytes) noexcept {
    std::uint8_t sum = 0;
    for (auto b : bytes)
        sum = static_cast<std::uint8_t>(sum + b);
    return static_cast<std::uint8_t>(-sum);
}

void write_rtu_frame(ByteWriter& w, Bytes pdu) noexcept {
    w.bytes(pdu);
    const std::uint16_t crc = crc16(pdu);
    w.u8(static_cast<std::uint8_t>(crc & 0xFFU));
    w.u8(static_cast<std::uint8_t>(crc >> 8));
}

bool rtu_crc_ok(Bytes frame) noexcept {
    if (frame.size() < 2 + crc_size) return false;
    const auto body = frame.first(frame.size() - crc_size);
    const std::uint16_t crc = crc16(body);
    return frame[frame.size() - 2] == (crc & 0xFFU) && frame[frame.size() - 1] == (crc >> 8);
}

std::optional<std::size_t> rtu_response_size(Bytes received) noexcept {
    if (received.size() < 2) return std::nullopt;
    const std::uint8_t function = received[1];
    if ((function & exception_bit) != 0) return 3 + crc_size;  // address, function, code
    switch (function) {
        case 0x01:  // read coils, discrete inputs, holding and input registers:
        case 0x02:  // address, function, byte count, data
        case 0x03:
        case 0x04:
        case 0x17:  // read/write multiple registers
            if (received.size() < 3) return std::nullopt;
            return 3 + std::size_t{received[2]} + crc_size;
        case 0x05:  // write single coil/register, write multiple: an 8-byte echo
        case 0x06:
        case 0x0F:
        case 0x10:
            return 6 + crc_size;
        case 0x16:  // mask write register
            return 8 + crc_size;
        default:
            return std::nullopt;
    }
}

bool write_ascii_frame(ByteWriter& w, Bytes ascii) noexcept {
    std::array<std::uint8_t, max_ascii_frame / 2> binary{};
    const auto n = hex_decode(ascii, binary);
    if (!n) return false;
    w.u8(':');
    w.bytes(ascii);
    hex_encode(w, std::array<std::uint8_t, 1>{lrc(Bytes{binary.data(), *n})});
    w.u8(cr);
    w.u8(lf);
    return true;
}

AsciiParse parse_ascii_frame(Bytes stream) noexcept {
    AsciiParse result;
    std::size_t start = stream.size();
    for (std::size_t i = 0; i < stream.size(); ++i) {
        if (stream[i] == ':') {
            start = i;
            continue;
        }
        if (start == stream.size()) continue;
        if (i - start > max_ascii_frame) {
            result.status = AsciiParse::Status::malformed;
            result.consumed = i;
            return result;
        }
        if (stream[i] != lf || stream[i - 1] != cr) continue;
        result.consumed = i + 1;
        // ':' digits LRC(2) CR LF
        const std::size_t digits_end = i - 1;
        if (digits_end < start + 1 + 2) {
            result.status = AsciiParse::Status::malformed;
            return result;
        }
        const Bytes all = stream.subspan(start + 1, digits_end - start - 1);
        std::array<std::uint8_t, max_ascii_frame / 2> binary{};
        const auto n = hex_decode(all, binary);
        if (!n || *n < 1) {
            result.status = AsciiParse::Status::malformed;
            return result;
        }
        // The LRC of the data bytes plus the LRC byte itself sums to zero.
        const Bytes data{binary.data(), *n - 1};
        result.ascii = all.first(all.size() - 2);
        result.status = lrc(data) == binary[*n - 1] ? AsciiParse::Status::complete
                                                    : AsciiParse::Status::bad_checksum;
        return result;
    }
    result.consumed = start == stream.size() ? stream.size() : start;
    return result;
}

std::optional<std::size_t> hex_decode(Bytes ascii, MutableBytes out) noexcept {
    if (ascii.size() % 2 != 0 || ascii.size() / 2 > out.size()) return std::nullopt;
    for (std::size_t i = 0; i < ascii.size(); i += 2) {
        const int b = hex::byte_value(static_cast<char>(ascii[i]), static_cast<char>(ascii[i + 1]));
        if (b < 0) return std::nullopt;
        out[i / 2] = static_cast<std::uint8_t>(b);
    }
    return ascii.size() / 2;
}

void hex_encode(ByteWriter& w, Bytes binary) noexcept {
    for (auto b : binary) {
        w.u8(digits[b >> 4U]);
        w.u8(digits[b & 0x0FU]);
    }
}

}  // namespace fins::modbus
