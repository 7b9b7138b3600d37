// MEMORY CASSETTE TRANSFER 22 20 (W342 5-3-43); layout choices in
// fins/commands/memory_cassette.hpp.
#include "fins/commands/memory_cassette.hpp"

#include "codec/command_codec.hpp"

namespace fins {

using codec::malformed;

namespace {

constexpr std::size_t command_size = 6;  // disk, parameter, designation

}  // namespace

void MemoryCassetteTransferResponse::encode(ByteWriter& w) const noexcept {
    w.u16(stored);
}

void MemoryCassetteTransfer::encode(ByteWriter& w) const noexcept {
    w.u16(disk);
    w.u16(operation);
    w.u16(designation);
}

Result<MemoryCassetteTransfer> MemoryCassetteTransfer::decode(Bytes parameters) {
    if (auto ec = codec::check_fixed(parameters, command_size)) return Unexpected(ec);
    ByteReader r(parameters);
    MemoryCassetteTransfer c;
    c.disk = r.u16();
    c.operation = r.u16();
    c.designation = r.u16();
    return c;
}

Result<MemoryCassetteTransfer::Response> MemoryCassetteTransfer::decode_response(Bytes data) const {
    if (operation != static_cast<std::uint16_t>(CassetteOperation::read_type)) {
        if (!data.empty()) return malformed();
        return Response{};
    }
    ByteReader r(data);
    Response out{r.u16()};
    if (r.truncated() || r.remaining() != 0) return malformed();
    return out;
}

}  // namespace fins
