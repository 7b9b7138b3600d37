// Helpers shared by the codec tests: hex text <-> bytes, golden vector files, and the
// "every shorter prefix fails" walk of the house style.
#pragma once

#include <cstdint>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include <gtest/gtest.h>

#include "fins/byte_io.hpp"
#include "fins/error.hpp"

namespace fins::test {

// "01 01 82" or "010182" -> bytes; throws on a bad digit so a typo fails loudly.
inline std::vector<std::uint8_t> hex(std::string_view text) {
    std::vector<std::uint8_t> out;
    int pending = -1;
    for (char c : text) {
        int v;
        if (c >= '0' && c <= '9')
            v = c - '0';
        else if (c >= 'A' && c <= 'F')
            v = c - 'A' + 10;
        else if (c >= 'a' && c <= 'f')
            v = c - 'a' + 10;
        else if (c == ' ' || c == '\t')
            continue;
        else
            throw std::invalid_argument("bad hex character");
        if (pending < 0) {
            pending = v;
        } else {
            out.push_back(static_cast<std::uint8_t>(pending * 16 + v));
            pending = -1;
        }
    }
    if (pending >= 0) throw std::invalid_argument("odd number of hex digits");
    return out;
}

// A golden vector file under tests/vectors/: "# source: ..." names where the bytes come
// from; other '#' lines are comments; every other non-empty line is data.
struct VectorFile {
    std::string source;
    std::vector<std::string> lines;
};

inline VectorFile load_vector(const std::string& name) {
    std::ifstream in(std::string(FINS_SOURCE_DIR) + "/tests/vectors/" + name);
    if (!in) throw std::runtime_error("cannot open vector " + name);
    VectorFile v;
    std::string line;
    while (std::getline(in, line)) {
        if (line.rfind("# source:", 0) == 0) v.source = line.substr(9);
        if (line.empty() || line[0] == '#') continue;
        v.lines.push_back(line);
    }
    return v;
}

// Encodes a command's parameters (or a response's data) into a fresh buffer.
template <class T>
std::vector<std::uint8_t> encode(const T& value, std::size_t capacity = 4096) {
    std::vector<std::uint8_t> buf(capacity);
    ByteWriter w(buf);
    value.encode(w);
    if (w.overflowed()) throw std::runtime_error("test buffer too small");
    buf.resize(w.size());
    return buf;
}

inline Bytes prefix(const std::vector<std::uint8_t>& v, std::size_t n) {
    return Bytes(v.data(), n);
}

// Every shorter prefix of a fixed-layout command's parameters decodes to 1002.
template <class C>
void expect_shorter_prefixes_fail(const std::vector<std::uint8_t>& params) {
    for (std::size_t n = 0; n < params.size(); ++n) {
        auto r = C::decode(prefix(params, n));
        ASSERT_FALSE(r) << C::name << " prefix " << n;
        EXPECT_EQ(r.error(), EndCode::command_too_short) << C::name << " prefix " << n;
    }
}

// One byte more than a fixed-length command takes decodes to 1001.
template <class C>
void expect_longer_fails(std::vector<std::uint8_t> params) {
    params.push_back(0x00);
    auto r = C::decode(params);
    ASSERT_FALSE(r) << C::name;
    EXPECT_EQ(r.error(), EndCode::command_too_long) << C::name;
}

}  // namespace fins::test
