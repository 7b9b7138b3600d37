// fins::Client typed reads and writes: the word order and encodings of fins/values.hpp
// (least significant word at the lower address, BCD, two ASCII characters per word)
// on top of read_words()/write_words().
#include "fins/client.hpp"
#include "fins/values.hpp"

namespace fins {

namespace {

// Reads `n` words and converts them with `decode` (one of the words_to_* functions).
template <class T, class Decode>
Result<T> read_as(Client& client, const Address& a, std::size_t n, Decode decode) {
    auto words = client.read_words(a, n);
    if (!words) return Unexpected(words.error());
    return decode(Words{*words});
}

template <std::size_t N>
Result<void> write_array(Client& client, const Address& a, const std::array<std::uint16_t, N>& w) {
    return client.write_words(a, std::span<const std::uint16_t>{w});
}

}  // namespace

Result<std::int16_t> Client::read_int16(const Address& a) {
    return read_as<std::int16_t>(*this, a, 1, words_to_int16);
}
Result<std::uint16_t> Client::read_uint16(const Address& a) {
    return read_as<std::uint16_t>(*this, a, 1, words_to_uint16);
}
Result<std::int32_t> Client::read_int32(const Address& a) {
    return read_as<std::int32_t>(*this, a, 2, words_to_int32);
}
Result<std::uint32_t> Client::read_uint32(const Address& a) {
    return read_as<std::uint32_t>(*this, a, 2, words_to_uint32);
}
Result<float> Client::read_float(const Address& a) {
    return read_as<float>(*this, a, 2, words_to_float);
}
Result<double> Client::read_double(const Address& a) {
    return read_as<double>(*this, a, 4, words_to_double);
}
Result<std::uint16_t> Client::read_bcd16(const Address& a) {
    return read_as<std::uint16_t>(*this, a, 1, words_to_bcd16);
}
Result<std::uint32_t> Client::read_bcd32(const Address& a) {
    return read_as<std::uint32_t>(*this, a, 2, words_to_bcd32);
}

Result<void> Client::write_int16(const Address& a, std::int16_t v) {
    return write_array(*this, a, int16_to_words(v));
}
Result<void> Client::write_uint16(const Address& a, std::uint16_t v) {
    return write_array(*this, a, uint16_to_words(v));
}
Result<void> Client::write_int32(const Address& a, std::int32_t v) {
    return write_array(*this, a, int32_to_words(v));
}
Result<void> Client::write_uint32(const Address& a, std::uint32_t v) {
    return write_array(*this, a, uint32_to_words(v));
}
Result<void> Client::write_float(const Address& a, float v) {
    return write_array(*this, a, float_to_words(v));
}
Result<void> Client::write_double(const Address& a, double v) {
    return write_array(*this, a, double_to_words(v));
}
Result<void> Client::write_bcd16(const Address& a, std::uint16_t v) {
    auto w = bcd16_to_words(v);
    if (!w) return Unexpected(w.error());
    return write_array(*this, a, *w);
}
Result<void> Client::write_bcd32(const Address& a, std::uint32_t v) {
    auto w = bcd32_to_words(v);
    if (!w) return Unexpected(w.error());
    return write_array(*this, a, *w);
}

Result<std::string> Client::read_string(const Address& a, std::size_t word_count) {
    auto words = read_words(a, word_count);
    if (!words) return Unexpected(words.error());
    return words_to_string(*words);
}

Result<void> Client::write_string(const Address& a, std::string_view s, std::size_t word_count) {
    auto words = word_count == 0 ? string_to_words(s) : string_to_words(s, word_count);
    if (!words) return Unexpected(words.error());
    return write_words(a, *words);
}

}  // namespace fins
