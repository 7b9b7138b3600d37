#include "client/fake_plc.hpp"

#include "fins/commands/memory_area.hpp"
#include "fins/memory_area.hpp"

namespace fins::test {

namespace {

constexpr std::uint16_t ok = 0x0000;
constexpr std::uint16_t area_missing = 0x1101;
constexpr std::uint16_t range_error = 0x1103;
constexpr std::uint16_t mismatch = 0x1003;
constexpr std::uint16_t undefined_command = 0x0401;

bool is_bit_code(std::uint8_t code) {
    return code == 0x02 || code == 0x30;
}

}  // namespace

std::vector<std::uint8_t> make_response(Bytes request, NodeAddress responder,
                                        std::uint16_t end_code, Bytes data) {
    auto req = decode_request(request);
    if (!req) return {};
    std::vector<std::uint8_t> out(max_frame_size);
    ByteWriter w(out);
    write_response_prefix(w, response_header(req->header, responder), req->command, end_code);
    w.bytes(data);
    out.resize(w.size());
    return out;
}

std::uint16_t* FakePlc::word(std::uint8_t area_code, std::uint32_t index) {
    switch (area_code) {
        case 0x02:
        case 0x82:
            return index < dm.size() ? &dm[index] : nullptr;
        case 0x30:
        case 0xB0:
            return index < cio.size() ? &cio[index] : nullptr;
        default:
            return nullptr;
    }
}

std::uint16_t FakePlc::read_element(std::uint8_t area_code, std::uint32_t w, std::uint8_t bit,
                                    bool& found) {
    auto* p = word(area_code, w);
    found = p != nullptr;
    if (!p) return 0;
    return is_bit_code(area_code) ? static_cast<std::uint16_t>((*p >> bit) & 1) : *p;
}

std::vector<std::uint8_t> FakePlc::handle(Bytes request) {
    auto req = decode_request(request);
    if (!req) return {};
    auto answer = execute(request);
    // A command with the no-response bit is executed, just not answered (frames 1.2).
    if (!req->header.response_required()) return {};
    return answer;
}

std::vector<std::uint8_t> FakePlc::execute(Bytes request) {
    auto req = decode_request(request);
    std::vector<std::uint8_t> data;
    std::uint16_t end = ok;
    auto linear = [](const MemoryAddress& a, std::size_t i, bool bits) {
        return bits ? std::uint32_t{a.word} * 16 + a.bit + static_cast<std::uint32_t>(i)
                    : std::uint32_t{a.word} + static_cast<std::uint32_t>(i);
    };
    const auto code = req->command.value();
    if (code == MemoryAreaRead::code.value()) {
        auto c = MemoryAreaRead::decode(req->parameters);
        if (!c) return make_response(request, self, static_cast<std::uint16_t>(c.error().value()));
        const bool bits = is_bit_code(c->start.area_code);
        if (element_size(c->start.area_code) == 0) end = area_missing;
        if (fail_word && c->start.word == *fail_word) end = range_error;
        for (std::size_t i = 0; end == ok && i < c->count; ++i) {
            auto at = linear(c->start, i, bits);
            bool found = false;
            auto v = read_element(c->start.area_code, bits ? at / 16 : at,
                                  static_cast<std::uint8_t>(at % 16), found);
            if (!found) end = range_error;
            if (bits)
                data.push_back(static_cast<std::uint8_t>(v));
            else {
                data.push_back(static_cast<std::uint8_t>(v >> 8));
                data.push_back(static_cast<std::uint8_t>(v));
            }
        }
    } else if (code == MemoryAreaWrite::code.value()) {
        auto c = MemoryAreaWrite::decode(req->parameters);
        if (!c) return make_response(request, self, static_cast<std::uint16_t>(c.error().value()));
        const bool bits = is_bit_code(c->start.area_code);
        const std::size_t size = element_size(c->start.area_code);
        if (size == 0)
            end = area_missing;
        else if (c->data.size() != size * c->count)
            end = mismatch;
        if (fail_word && c->start.word == *fail_word) end = range_error;
        for (std::size_t i = 0; end == ok && i < c->count; ++i) {
            auto at = linear(c->start, i, bits);
            auto* p = word(c->start.area_code, bits ? at / 16 : at);
            if (!p) {
                end = range_error;
            } else if (bits) {
                const auto mask = static_cast<std::uint16_t>(1u << (at % 16));
                *p = static_cast<std::uint16_t>(c->data[i] ? (*p | mask) : (*p & ~mask));
            } else {
                *p = static_cast<std::uint16_t>((c->data[2 * i] << 8) | c->data[2 * i + 1]);
            }
        }
    } else if (code == MemoryAreaFill::code.value()) {
        auto c = MemoryAreaFill::decode(req->parameters);
        if (!c) return make_response(request, self, static_cast<std::uint16_t>(c.error().value()));
        for (std::size_t i = 0; end == ok && i < c->count; ++i) {
            auto* p = word(c->start.area_code, c->start.word + static_cast<std::uint32_t>(i));
            if (p)
                *p = c->value;
            else
                end = range_error;
        }
    } else if (code == MemoryAreaTransfer::code.value()) {
        auto c = MemoryAreaTransfer::decode(req->parameters);
        if (!c) return make_response(request, self, static_cast<std::uint16_t>(c.error().value()));
        std::vector<std::uint16_t> copy;
        for (std::size_t i = 0; end == ok && i < c->count; ++i) {
            auto* p = word(c->source.area_code, c->source.word + static_cast<std::uint32_t>(i));
            if (p)
                copy.push_back(*p);
            else
                end = range_error;
        }
        for (std::size_t i = 0; end == ok && i < copy.size(); ++i) {
            auto* p =
                word(c->destination.area_code, c->destination.word + static_cast<std::uint32_t>(i));
            if (p)
                *p = copy[i];
            else
                end = range_error;
        }
    } else if (code == MultipleMemoryAreaRead::code.value()) {
        auto c = MultipleMemoryAreaRead::decode(req->parameters);
        if (!c) return make_response(request, self, static_cast<std::uint16_t>(c.error().value()));
        for (const auto& item : c->items) {
            bool found = false;
            auto v = read_element(item.area_code, item.word, item.bit, found);
            if (!found) {
                end = range_error;
                break;
            }
            data.push_back(item.area_code);
            if (!is_bit_code(item.area_code)) data.push_back(static_cast<std::uint8_t>(v >> 8));
            data.push_back(static_cast<std::uint8_t>(v));
        }
    } else {
        end = undefined_command;
    }
    if (end != ok) data.clear();
    return make_response(request, self, static_cast<std::uint16_t>(end | end_code_flags), data);
}

}  // namespace fins::test
