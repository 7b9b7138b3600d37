// Fuzzes the Host Link FINS codec the way a serial session drives it: the frame finder
// over the byte stream, then every frame decoded as a command and as a response; what
// decodes is encoded back and must decode to the same FINS frame.
#include <array>
#include <cstddef>
#include <cstdint>

#include "fins/frame.hpp"
#include "fins/host_link.hpp"

namespace {
void check(bool ok) {
    if (!ok) __builtin_trap();
}

void round_trip(fins::Bytes frame, bool response) {
    using namespace fins;
    std::array<std::uint8_t, host_link_max_fins_response> fins{};
    auto f = decode_host_link(frame, response, fins);
    if (!f) {
        (void)host_link_answer_for(f.error());
        return;
    }
    check(f->fins_size <= fins.size());
    if (f->fins_size == 0) return;  // an error answer
    const Bytes decoded{fins.data(), f->fins_size};
    std::array<std::uint8_t, 2 * host_link_max_response_chars> out{};
    auto n = response ? encode_host_link_response(f->unit, f->form, decoded, out, f->header_code)
                      : encode_host_link_command(f->unit, f->wait, f->form, decoded, out,
                                                 f->header_code);
    check(n.has_value());
    std::array<std::uint8_t, host_link_max_fins_response> again{};
    auto g = decode_host_link(Bytes{out.data(), *n}, response, again);
    check(g.has_value() && g->fins_size == f->fins_size);
    // The direct form does not carry RSV, GCT and the network/node bytes.
    for (std::size_t i = 0; i < f->fins_size; ++i)
        if (f->form == HostLinkForm::network || i == 5 || i >= 8) check(again[i] == fins[i]);
    if (response)
        (void)decode_response(decoded);
    else
        (void)decode_request(decoded);
}
}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    using namespace fins;
    Bytes buffer(data, size);
    while (!buffer.empty()) {
        const auto s = scan_host_link(buffer);
        check(s.consumed <= buffer.size());
        if (s.status == HostLinkScan::Status::need_more) break;
        check(s.consumed > 0);
        if (s.status == HostLinkScan::Status::frame) {
            check(s.frame.size() == s.consumed && s.frame.size() <= host_link_max_response_chars);
            round_trip(s.frame, false);
            round_trip(s.frame, true);
        }
        buffer = buffer.subspan(s.consumed);
    }
    return 0;
}
