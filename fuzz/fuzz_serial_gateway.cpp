// Fuzzes the Serial Gateway decoders: the 28 03/04/05 FINS bodies, the CompoWay/F,
// Modbus-RTU and Modbus-ASCII stream parsers. The first byte picks the decoder. Checks:
// no crash, consumed within the input, whatever decodes encodes back to the same bytes.
#include <cstddef>
#include <cstdint>
#include <vector>

#include "fins/commands/serial_gateway.hpp"
#include "fins/compoway_f.hpp"
#include "fins/modbus.hpp"

namespace {

void check(bool ok) {
    if (!ok) __builtin_trap();
}

template <class C>
void round_trip(fins::Bytes input) {
    const auto decoded = C::decode(input);
    if (!decoded) return;
    std::vector<std::uint8_t> out(input.size() + 16);
    fins::ByteWriter w(out);
    decoded->encode(w);
    check(!w.overflowed() && w.size() == input.size() &&
          std::equal(input.begin(), input.end(), out.begin()));
    (void)decoded->decode_response(input);
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    using namespace fins;
    if (size == 0) return 0;
    const Bytes input{data + 1, size - 1};
    switch (data[0] % 6) {
        case 0:
            round_trip<ConvertToCompowayF>(input);
            break;
        case 1:
            round_trip<ConvertToModbusRtu>(input);
            break;
        case 2:
            round_trip<ConvertToModbusAscii>(input);
            break;
        case 3: {
            const auto parsed = compoway_f::parse_frame(input);
            check(parsed.consumed <= input.size());
            if (parsed.status != compoway_f::FrameParse::Status::complete) break;
            if (const auto r = compoway_f::decode_response(parsed.body)) {
                std::vector<std::uint8_t> out(parsed.body.size());
                ByteWriter w(out);
                compoway_f::encode_response(w, *r);
                check(w.size() == parsed.body.size() &&
                      std::equal(out.begin(), out.end(), parsed.body.begin()));
            }
            break;
        }
        case 4: {
            const auto parsed = modbus::parse_ascii_frame(input);
            check(parsed.consumed <= input.size());
            if (parsed.status != modbus::AsciiParse::Status::complete) break;
            std::vector<std::uint8_t> out(parsed.ascii.size() + 5);
            ByteWriter w(out);
            check(modbus::write_ascii_frame(w, parsed.ascii));
            break;
        }
        default: {
            const auto expected = modbus::rtu_response_size(input);
            if (expected && *expected <= input.size() && modbus::rtu_crc_ok(input.first(*expected)))
                check(*expected >= 4);
            break;
        }
    }
    return 0;
}
