// Bounds-checked big-endian cursors over byte spans.
//
// Every FINS field is big-endian (W342 5-2-1). Decoders read through ByteReader and
// never cast structs over untrusted bytes: a read past the end returns 0 and marks the
// reader truncated, so a decoder can read all fields and check once at the end.
// ByteWriter writes into a caller-owned fixed buffer (no allocation); writing past the
// end marks it overflowed instead of writing.
#pragma once

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <span>
#include <string_view>

namespace fins {

using Bytes = std::span<const std::uint8_t>;
using MutableBytes = std::span<std::uint8_t>;

class ByteReader {
  public:
    constexpr explicit ByteReader(Bytes data) noexcept : data_(data) {}

    constexpr std::uint8_t u8() noexcept {
        if (!need(1)) return 0;
        return data_[pos_++];
    }
    constexpr std::uint16_t u16() noexcept {
        if (!need(2)) return 0;
        auto v = static_cast<std::uint16_t>((data_[pos_] << 8) | data_[pos_ + 1]);
        pos_ += 2;
        return v;
    }
    constexpr std::uint32_t u24() noexcept {
        if (!need(3)) return 0;
        auto v = (std::uint32_t{data_[pos_]} << 16) | (std::uint32_t{data_[pos_ + 1]} << 8) |
                 std::uint32_t{data_[pos_ + 2]};
        pos_ += 3;
        return v;
    }
    constexpr std::uint32_t u32() noexcept {
        if (!need(4)) return 0;
        auto v = (std::uint32_t{data_[pos_]} << 24) | (std::uint32_t{data_[pos_ + 1]} << 16) |
                 (std::uint32_t{data_[pos_ + 2]} << 8) | std::uint32_t{data_[pos_ + 3]};
        pos_ += 4;
        return v;
    }
    // Returns a view of the next n bytes (empty and truncated if fewer remain).
    constexpr Bytes bytes(std::size_t n) noexcept {
        if (!need(n)) return {};
        auto v = data_.subspan(pos_, n);
        pos_ += n;
        return v;
    }
    constexpr Bytes rest() noexcept {
        auto v = data_.subspan(pos_);
        pos_ = data_.size();
        return v;
    }
    constexpr void skip(std::size_t n) noexcept {
        if (need(n)) pos_ += n;
    }

    [[nodiscard]] constexpr std::size_t remaining() const noexcept { return data_.size() - pos_; }
    [[nodiscard]] constexpr std::size_t position() const noexcept { return pos_; }
    [[nodiscard]] constexpr bool truncated() const noexcept { return truncated_; }
    // True when every field read so far was present and nothing is left over.
    [[nodiscard]] constexpr bool complete() const noexcept {
        return !truncated_ && pos_ == data_.size();
    }

  private:
    constexpr bool need(std::size_t n) noexcept {
        if (truncated_ || data_.size() - pos_ < n) {
            truncated_ = true;
            return false;
        }
        return true;
    }

    Bytes data_;
    std::size_t pos_ = 0;
    bool truncated_ = false;
};

class ByteWriter {
  public:
    constexpr explicit ByteWriter(MutableBytes out) noexcept : out_(out) {}

    constexpr void u8(std::uint8_t v) noexcept {
        if (room(1)) out_[pos_++] = v;
    }
    constexpr void u16(std::uint16_t v) noexcept {
        if (!room(2)) return;
        out_[pos_++] = static_cast<std::uint8_t>(v >> 8);
        out_[pos_++] = static_cast<std::uint8_t>(v);
    }
    constexpr void u24(std::uint32_t v) noexcept {
        if (!room(3)) return;
        out_[pos_++] = static_cast<std::uint8_t>(v >> 16);
        out_[pos_++] = static_cast<std::uint8_t>(v >> 8);
        out_[pos_++] = static_cast<std::uint8_t>(v);
    }
    constexpr void u32(std::uint32_t v) noexcept {
        if (!room(4)) return;
        out_[pos_++] = static_cast<std::uint8_t>(v >> 24);
        out_[pos_++] = static_cast<std::uint8_t>(v >> 16);
        out_[pos_++] = static_cast<std::uint8_t>(v >> 8);
        out_[pos_++] = static_cast<std::uint8_t>(v);
    }
    constexpr void bytes(Bytes v) noexcept {
        if (!room(v.size())) return;
        // One block copy (memmove at run time): a byte loop through out_[pos_++] cannot be
        // vectorized, since a byte store may alias pos_ (22 02/22 03 chunks of ~2 KB).
        std::copy(v.begin(), v.end(), out_.begin() + static_cast<std::ptrdiff_t>(pos_));
        pos_ += v.size();
    }
    // Writes s padded with `pad` (or cut) to exactly n bytes.
    constexpr void text(std::string_view s, std::size_t n, std::uint8_t pad = 0x20) noexcept {
        if (!room(n)) return;
        for (std::size_t i = 0; i < n; ++i)
            out_[pos_++] = i < s.size() ? static_cast<std::uint8_t>(s[i]) : pad;
    }
    // Reserves n bytes to fill later (e.g. a count known only at the end).
    constexpr MutableBytes reserve(std::size_t n) noexcept {
        if (!room(n)) return {};
        auto v = out_.subspan(pos_, n);
        pos_ += n;
        return v;
    }

    [[nodiscard]] constexpr std::size_t size() const noexcept { return pos_; }
    [[nodiscard]] constexpr std::size_t remaining() const noexcept { return out_.size() - pos_; }
    [[nodiscard]] constexpr bool overflowed() const noexcept { return overflowed_; }
    [[nodiscard]] constexpr Bytes written() const noexcept { return out_.first(pos_); }
    constexpr void rewind(std::size_t pos) noexcept {
        if (pos <= pos_) pos_ = pos;
        overflowed_ = false;
    }

  private:
    constexpr bool room(std::size_t n) noexcept {
        if (overflowed_ || out_.size() - pos_ < n) {
            overflowed_ = true;
            return false;
        }
        return true;
    }

    MutableBytes out_;
    std::size_t pos_ = 0;
    bool overflowed_ = false;
};

}  // namespace fins
