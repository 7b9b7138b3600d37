// fins::Client I/O memory helpers over 01 01 .. 01 05 (W342 5-3-2 .. 5-3-6).
//
// Long reads and writes are cut at the Ethernet element limits (W342 5-2-2 "Number of
// Elements": 999 read, 997 written) and the parts are submitted together, so they are
// in flight at the same time; the call returns when every part has ended and fails with
// the first error any part reported.
#include <algorithm>
#include <memory>

#include "fins/client.hpp"
#include "fins/memory_area.hpp"
#include "fins/values.hpp"

namespace fins {

namespace {

// Shared by the parts of one helper call; shared so no callback can outlive it.
struct Batch {
    std::size_t remaining = 0;
    std::error_code error;
    void fail(std::error_code ec) {
        if (!error) error = ec;
    }
};

std::error_code invalid() {
    return make_error_code(ClientError::invalid_argument);
}

// The memory address `offset` elements after `start`. Bit elements step through the
// bits of consecutive words; words and per-word flags step by word.
MemoryAddress advance(const MemoryAddress& start, std::size_t offset, bool bit_steps) {
    MemoryAddress a = start;
    if (bit_steps) {
        const std::size_t linear = std::size_t{start.word} * 16 + start.bit + offset;
        a.word = static_cast<std::uint16_t>(linear / 16);
        a.bit = static_cast<std::uint8_t>(linear % 16);
    } else {
        a.word = static_cast<std::uint16_t>(start.word + offset);
    }
    return a;
}

// Refuses ranges that run past word FFFF of the area code.
bool fits(const MemoryAddress& start, std::size_t count, bool bit_steps) {
    if (count == 0) return true;
    if (bit_steps)
        return std::size_t{start.word} * 16 + start.bit + count <= std::size_t{0x10000} * 16;
    return std::size_t{start.word} + count <= 0x10000;
}

bool steps_by_bit(const MemoryAddress& a) {
    const auto* segment = find_segment(a.area_code, a.word);
    return segment != nullptr && segment->bit_addressed();
}

// Elements per request: W342 5-2-2 (999 read, 997 written, 167 for 01 04 over Ethernet),
// or what the link's frame holds (Host Link: 269 read, 267 written, W342 5-2-2 SYSWAY).
constexpr std::size_t write_fixed = 6;  // 01 02: area, address, count
std::size_t read_limit(const Client& c) {
    return std::min<std::size_t>(max_read_words, c.max_response_data() / 2);
}
std::size_t write_limit(const Client& c) {
    return std::min<std::size_t>(max_write_words, (c.max_parameters() - write_fixed) / 2);
}
// 01 04: 4 request bytes per element; up to 5 answer bytes (area code + 4-byte value).
std::size_t multiple_limit(const Client& c) {
    return std::min(
        {max_multiple_read_elements, c.max_parameters() / 4, c.max_response_data() / 5});
}

}  // namespace

Result<std::vector<std::uint16_t>> Client::read_words(const Address& start, std::size_t count) {
    if (in_callback()) return Unexpected(make_error_code(ClientError::called_from_callback));
    auto mem = to_memory_address(start, Access::word);
    if (!mem) return Unexpected(mem.error());
    if (element_size(mem->area_code) != 2 || !fits(*mem, count, false))
        return Unexpected(invalid());
    auto batch = std::make_shared<Batch>();
    auto words = std::make_shared<std::vector<std::uint16_t>>(count);
    for (std::size_t offset = 0; offset < count; offset += read_limit(*this)) {
        const auto n = std::min<std::size_t>(read_limit(*this), count - offset);
        MemoryAreaRead command{advance(*mem, offset, false), static_cast<std::uint16_t>(n)};
        ++batch->remaining;
        async_send(command, [batch, words, offset](Result<MemoryAreaReadResponse> r) {
            --batch->remaining;
            if (!r) return batch->fail(r.error());
            auto part = bytes_to_words(r->data);
            if (!part) return batch->fail(make_error_code(ClientError::malformed_response));
            std::copy(part->begin(), part->end(),
                      words->begin() + static_cast<std::ptrdiff_t>(offset));
        });
    }
    run_until([&batch] { return batch->remaining == 0; });
    if (batch->error) return Unexpected(batch->error);
    return std::move(*words);
}

Result<void> Client::write_words(const Address& start, std::span<const std::uint16_t> words) {
    if (in_callback()) return Unexpected(make_error_code(ClientError::called_from_callback));
    auto mem = to_memory_address(start, Access::word);
    if (!mem) return Unexpected(mem.error());
    if (element_size(mem->area_code) != 2 || !fits(*mem, words.size(), false))
        return Unexpected(invalid());
    const auto bytes = words_to_bytes(words);
    auto batch = std::make_shared<Batch>();
    for (std::size_t offset = 0; offset < words.size(); offset += write_limit(*this)) {
        const auto n = std::min<std::size_t>(write_limit(*this), words.size() - offset);
        MemoryAreaWrite command{advance(*mem, offset, false), static_cast<std::uint16_t>(n),
                                Bytes{bytes}.subspan(offset * 2, n * 2)};
        ++batch->remaining;
        async_send(command, [batch](Result<EmptyResponse> r) {
            --batch->remaining;
            if (!r) batch->fail(r.error());
        });
    }
    run_until([&batch] { return batch->remaining == 0; });
    if (batch->error) return Unexpected(batch->error);
    return {};
}

Result<std::vector<bool>> Client::read_bits(const Address& start, std::size_t count) {
    if (in_callback()) return Unexpected(make_error_code(ClientError::called_from_callback));
    auto mem = to_memory_address(start, Access::bit);
    if (!mem) return Unexpected(mem.error());
    const bool bit_steps = steps_by_bit(*mem);
    if (element_size(mem->area_code) != 1 || !fits(*mem, count, bit_steps))
        return Unexpected(invalid());
    auto batch = std::make_shared<Batch>();
    auto bits = std::make_shared<std::vector<bool>>(count);
    for (std::size_t offset = 0; offset < count; offset += read_limit(*this)) {
        const auto n = std::min<std::size_t>(read_limit(*this), count - offset);
        MemoryAreaRead command{advance(*mem, offset, bit_steps), static_cast<std::uint16_t>(n)};
        ++batch->remaining;
        async_send(command, [batch, bits, offset](Result<MemoryAreaReadResponse> r) {
            --batch->remaining;
            if (!r) return batch->fail(r.error());
            // Bit 0 is the value; bit 1 is the forced flag of the "with forced status" codes.
            for (std::size_t i = 0; i < r->data.size(); ++i)
                (*bits)[offset + i] = (r->data[i] & 1) != 0;
        });
    }
    run_until([&batch] { return batch->remaining == 0; });
    if (batch->error) return Unexpected(batch->error);
    return std::move(*bits);
}

Result<void> Client::write_bits(const Address& start, const std::vector<bool>& bits) {
    if (in_callback()) return Unexpected(make_error_code(ClientError::called_from_callback));
    auto mem = to_memory_address(start, Access::bit);
    if (!mem) return Unexpected(mem.error());
    const bool bit_steps = steps_by_bit(*mem);
    if (element_size(mem->area_code) != 1 || !fits(*mem, bits.size(), bit_steps))
        return Unexpected(invalid());
    std::vector<std::uint8_t> bytes(bits.size());
    for (std::size_t i = 0; i < bits.size(); ++i)
        bytes[i] = bits[i] ? 1 : 0;
    auto batch = std::make_shared<Batch>();
    for (std::size_t offset = 0; offset < bits.size(); offset += write_limit(*this)) {
        const auto n = std::min<std::size_t>(write_limit(*this), bits.size() - offset);
        MemoryAreaWrite command{advance(*mem, offset, bit_steps), static_cast<std::uint16_t>(n),
                                Bytes{bytes}.subspan(offset, n)};
        ++batch->remaining;
        async_send(command, [batch](Result<EmptyResponse> r) {
            --batch->remaining;
            if (!r) batch->fail(r.error());
        });
    }
    run_until([&batch] { return batch->remaining == 0; });
    if (batch->error) return Unexpected(batch->error);
    return {};
}

Result<void> Client::fill(const Address& start, std::size_t count, std::uint16_t value) {
    auto mem = to_memory_address(start, Access::word);
    if (!mem) return Unexpected(mem.error());
    if (count > 0xFFFF || !fits(*mem, count, false)) return Unexpected(invalid());
    auto r = send(MemoryAreaFill{*mem, static_cast<std::uint16_t>(count), value});
    if (!r) return Unexpected(r.error());
    return {};
}

Result<void> Client::transfer(const Address& from, const Address& to, std::size_t count) {
    auto source = to_memory_address(from, Access::word);
    if (!source) return Unexpected(source.error());
    auto destination = to_memory_address(to, Access::word);
    if (!destination) return Unexpected(destination.error());
    if (count > 0xFFFF || !fits(*source, count, false) || !fits(*destination, count, false))
        return Unexpected(invalid());
    auto r = send(MemoryAreaTransfer{*source, *destination, static_cast<std::uint16_t>(count)});
    if (!r) return Unexpected(r.error());
    return {};
}

Result<std::vector<std::uint32_t>> Client::read_multiple(std::span<const Address> addresses) {
    if (in_callback()) return Unexpected(make_error_code(ClientError::called_from_callback));
    std::vector<MemoryAddress> items;
    items.reserve(addresses.size());
    for (const auto& a : addresses) {
        auto mem = to_memory_address(a);
        if (!mem) return Unexpected(mem.error());
        items.push_back(*mem);
    }
    auto batch = std::make_shared<Batch>();
    auto values = std::make_shared<std::vector<std::uint32_t>>(items.size());
    for (std::size_t offset = 0; offset < items.size(); offset += multiple_limit(*this)) {
        const auto n = std::min(multiple_limit(*this), items.size() - offset);
        MultipleMemoryAreaRead command;
        command.items.assign(items.begin() + static_cast<std::ptrdiff_t>(offset),
                             items.begin() + static_cast<std::ptrdiff_t>(offset + n));
        ++batch->remaining;
        async_send(command, [batch, values, offset, n](Result<MultipleMemoryAreaReadResponse> r) {
            --batch->remaining;
            if (!r) return batch->fail(r.error());
            if (r->items.size() != n)
                return batch->fail(make_error_code(ClientError::malformed_response));
            for (std::size_t i = 0; i < n; ++i)
                (*values)[offset + i] = r->items[i].value;
        });
    }
    run_until([&batch] { return batch->remaining == 0; });
    if (batch->error) return Unexpected(batch->error);
    return std::move(*values);
}

}  // namespace fins
