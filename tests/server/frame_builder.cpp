#include "server/frame_builder.hpp"

#include <stdexcept>
#include <utility>

#include "../fuzz/corpus_dump.hpp"

namespace fins::test {

namespace {

int nibble(char c) {
    if (c >= '0' && c <= '9') return c - '0';
    if (c >= 'a' && c <= 'f') return c - 'a' + 10;
    if (c >= 'A' && c <= 'F') return c - 'A' + 10;
    throw std::invalid_argument("not a hex digit in test frame text");
}

}  // namespace

std::vector<std::uint8_t> hex(std::string_view text) {
    std::vector<std::uint8_t> out;
    int high = -1;
    for (char c : text) {
        if (c == ' ') continue;
        const int v = nibble(c);
        if (high < 0) {
            high = v;
        } else {
            out.push_back(static_cast<std::uint8_t>((high << 4) | v));
            high = -1;
        }
    }
    if (high >= 0) throw std::invalid_argument("odd number of hex digits in test frame text");
    return out;
}

std::string to_hex(Bytes bytes) {
    static constexpr char digits[] = "0123456789ABCDEF";
    std::string s;
    for (std::size_t i = 0; i < bytes.size(); ++i) {
        if (i != 0) s += ' ';
        s += digits[bytes[i] >> 4];
        s += digits[bytes[i] & 0x0F];
    }
    return s;
}

std::vector<std::uint8_t> request_frame(std::string_view command_hex, const FrameFields& f) {
    std::vector<std::uint8_t> frame{f.icf,
                                    f.reserved,
                                    f.gateway_count,
                                    f.destination.network,
                                    f.destination.node,
                                    f.destination.unit,
                                    f.source.network,
                                    f.source.node,
                                    f.source.unit,
                                    f.service_id};
    const auto body = hex(command_hex);
    frame.insert(frame.end(), body.begin(), body.end());
    return frame;
}

Header Reply::header() const {
    ByteReader r(frame);
    return read_header(r);
}

CommandCode Reply::command() const {
    if (frame.size() < header_size + command_code_size) return {};
    return {frame[header_size], frame[header_size + 1]};
}

std::uint16_t Reply::end_code() const {
    if (frame.size() < header_size + command_code_size + end_code_size) return 0xFFFF;
    return static_cast<std::uint16_t>((frame[12] << 8) | frame[13]);
}

std::vector<std::uint8_t> Reply::data() const {
    const std::size_t start = header_size + command_code_size + end_code_size;
    if (frame.size() <= start) return {};
    return {frame.begin() + static_cast<std::ptrdiff_t>(start), frame.end()};
}

Harness::Harness(plc::Profile profile) : plc(std::move(profile)), dispatcher(plc, server_node) {}

Reply Harness::send(Bytes frame) {
    fuzz::dump_test_bytes("request", frame);  // FINS_FUZZ_DUMP: fuzz/make_corpus.sh
    const auto n = dispatcher.handle(frame, out_, context);
    fuzz::dump_test_bytes("response", {out_.data(), n});
    return Reply{
        std::vector<std::uint8_t>(out_.begin(), out_.begin() + static_cast<std::ptrdiff_t>(n))};
}

Reply Harness::send(std::string_view command_hex, const FrameFields& f) {
    const auto frame = request_frame(command_hex, f);
    return send(frame);
}

}  // namespace fins::test
