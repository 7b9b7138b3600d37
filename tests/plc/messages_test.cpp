// plc::Messages: MSG 0-7 registration and clearing (W342 5-3-21, 5-3-22, 5-3-17).
#include <gtest/gtest.h>

#include <string>

#include "plc/plc.hpp"

namespace fins::plc {
namespace {

TEST(Messages, W342_5_3_21_SetReadAndClear) {
    Plc plc;
    auto& m = plc.messages();
    EXPECT_EQ(m.present(), 0);
    EXPECT_TRUE(m.set(0, "PUMP 1 STARTED"));
    EXPECT_TRUE(m.set(7, std::string(32, 'Z')));
    EXPECT_EQ(m.present(), 0x81);
    EXPECT_EQ(m.text(0), "PUMP 1 STARTED");
    EXPECT_EQ(m.text(7), std::string(32, 'Z'));
    EXPECT_TRUE(m.registered(7));
    EXPECT_FALSE(m.registered(1));
    EXPECT_EQ(m.text(1), "");
    m.clear(0x01);
    EXPECT_EQ(m.present(), 0x80);
    EXPECT_EQ(m.text(0), "");
    m.clear(0xFF);
    EXPECT_EQ(m.present(), 0x00);
}

TEST(Messages, W342_5_3_21_RangesAreChecked) {
    Plc plc;
    auto& m = plc.messages();
    EXPECT_FALSE(m.set(8, "X"));
    EXPECT_FALSE(m.set(0, std::string(33, 'x')));
    EXPECT_EQ(m.present(), 0);
    EXPECT_FALSE(m.registered(100));
    EXPECT_EQ(m.text(100), "");
    EXPECT_TRUE(m.set(2, ""));  // registered, reads as spaces
    EXPECT_TRUE(m.registered(2));
    EXPECT_TRUE(m.set(2, "SHORTER"));
    EXPECT_EQ(m.text(2), "SHORTER");
}

}  // namespace
}  // namespace fins::plc
