// Shared helpers for the bridge tests: configs from text.
#pragma once

#include <string>

#include <gtest/gtest.h>

#include "bridge/config.hpp"

namespace fins::bridge::test {

// A config with one PLC and one group holding `tags` (TOML inline tables).
inline std::string one_group(const std::string& tags, const std::string& group_extra = "") {
    return "[[plc]]\nname = \"p\"\nhost = \"127.0.0.1\"\n[[plc.group]]\nname = \"g\"\n" +
           group_extra + "tags = [" + tags + "]\n";
}

inline BridgeConfig parse_ok(const std::string& text) {
    auto c = parse_config(text, "t.toml", "test");
    EXPECT_TRUE(c.has_value()) << (c ? "" : c.error());
    return c ? *c : BridgeConfig{};
}

inline std::string parse_error(const std::string& text) {
    auto c = parse_config(text, "t.toml", "test");
    EXPECT_FALSE(c.has_value());
    return c ? std::string() : c.error();
}

}  // namespace fins::bridge::test
