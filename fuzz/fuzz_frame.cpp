// Fuzzes the frame codecs and every 01 xx command decoder, server side (decode) and
// client side (decode_response). Invariants checked beyond "does not crash":
// whatever decodes re-encodes to the same bytes.
#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "fins/commands/memory_area.hpp"
#include "fins/frame.hpp"

namespace {

using namespace fins;

void check(bool ok) {
    if (!ok) __builtin_trap();
}

template <class T>
std::vector<std::uint8_t> encoded(const T& value) {
    // Room for any input libFuzzer makes (-max_len defaults to 4096) plus slack.
    std::vector<std::uint8_t> buf(8192);
    ByteWriter w(buf);
    value.encode(w);
    check(!w.overflowed());
    buf.resize(w.size());
    return buf;
}

bool same(const std::vector<std::uint8_t>& a, Bytes b) {
    return a.size() == b.size() && std::equal(a.begin(), a.end(), b.begin());
}

// Server side: the parameters of a request.
void fuzz_commands(Bytes params) {
    if (auto c = MemoryAreaRead::decode(params)) check(same(encoded(*c), params));
    if (auto c = MemoryAreaWrite::decode(params)) check(same(encoded(*c), params));
    if (auto c = MemoryAreaFill::decode(params)) check(same(encoded(*c), params));
    if (auto c = MultipleMemoryAreaRead::decode(params)) check(same(encoded(*c), params));
    if (auto c = MemoryAreaTransfer::decode(params)) check(same(encoded(*c), params));
}

// Client side: a request built from the first bytes, the rest as its response data.
void fuzz_responses(Bytes in) {
    ByteReader r(in);
    MemoryAreaRead read;
    read.start = {r.u8(), r.u16(), r.u8()};
    read.count = r.u16();
    const auto data = r.rest();
    if (auto rsp = read.decode_response(data)) check(same(encoded(*rsp), data));

    MultipleMemoryAreaRead multi;
    ByteReader m(in);
    const auto n = m.u8() % 8;
    for (int i = 0; i < n; ++i)
        multi.items.push_back({m.u8(), m.u16(), m.u8()});
    const auto multi_data = m.rest();
    if (auto rsp = multi.decode_response(multi_data)) check(same(encoded(*rsp), multi_data));

    (void)MemoryAreaWrite{}.decode_response(data);
    (void)MemoryAreaFill{}.decode_response(data);
    (void)MemoryAreaTransfer{}.decode_response(data);
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    const Bytes in(data, size);
    if (auto req = decode_request(in)) {
        check(!req->header.is_response());
        std::vector<std::uint8_t> out(max_frame_size);
        auto n = encode_request(req->header, req->command, req->parameters, out);
        check(n.has_value() && *n == size && std::equal(data, data + size, out.begin()));
        fuzz_commands(req->parameters);
    }
    if (auto rsp = decode_response(in)) {
        check(rsp->header.is_response());
        check(rsp->relay.has_value() == rsp->code.relay_error());
        fuzz_responses(rsp->data);
    }
    fuzz_commands(in);
    fuzz_responses(in);
    return 0;
}
