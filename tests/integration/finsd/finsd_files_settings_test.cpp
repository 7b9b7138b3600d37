// finsd's [files] keys (README "File memory (22 xx)"): memory card inserted and its
// capacity, the first EM file bank, each checked with the key named on error.
#include <gtest/gtest.h>

#include "finsd/config.hpp"

namespace fins::finsd {
namespace {

Expected<Settings> load(std::string_view text) {
    Settings s;
    if (auto r = load_config_text(text, "t.toml", s); !r) return tl::unexpected(r.error());
    return s;
}

TEST(FinsdFilesSettings, CardAndEmFileBank) {
    auto s = load("[files]\ncard_kbytes = 2048\nem_file_bank = 16\n");
    ASSERT_TRUE(s) << s.error();
    EXPECT_EQ(s->card_kbytes, 2048u);
    EXPECT_EQ(s->em_file_bank, 16);
    EXPECT_TRUE(validate(*s));
    s = load("[files]\ncard = false\ncard_kbytes = 2048\n");
    ASSERT_TRUE(s);
    EXPECT_EQ(s->card_kbytes, 0u);  // no card: the capacity waits for an insert
    s = load("");
    ASSERT_TRUE(s);
    EXPECT_FALSE(s->card_kbytes || s->em_file_bank);  // the profile's
}

TEST(FinsdFilesSettings, BadValuesNameTheKey) {
    auto s = load("[files]\ncard_kbytes = 0\n");
    ASSERT_FALSE(s);
    EXPECT_NE(s.error().find("files.card_kbytes"), std::string::npos) << s.error();
    s = load("[files]\nem_file_bank = 25\n");
    ASSERT_FALSE(s);
    EXPECT_NE(s.error().find("files.em_file_bank"), std::string::npos) << s.error();
    s = load("[files]\nslots = 2\n");
    ASSERT_FALSE(s);
    EXPECT_NE(s.error().find("files.slots: unknown key"), std::string::npos) << s.error();
    // A bank the profile does not have: the CJ1M has no EM at all.
    s = load("profile = \"cj1m\"\n[files]\nem_file_bank = 0\n");
    ASSERT_TRUE(s);
    const auto v = validate(*s);
    ASSERT_FALSE(v);
    EXPECT_NE(v.error().find("files.em_file_bank"), std::string::npos) << v.error();
}

TEST(FinsdFilesSettings, CassetteOnlyWhereTheProfileHasASlot) {
    auto s = load("profile = \"cp1h\"\n[files]\ncassette = false\n");
    ASSERT_TRUE(s) << s.error();
    EXPECT_EQ(s->cassette, false);
    EXPECT_TRUE(validate(*s));
    s = load("[files]\ncassette = true\n");  // the default CJ2H
    ASSERT_TRUE(s) << s.error();
    const auto v = validate(*s);
    ASSERT_FALSE(v);
    EXPECT_NE(v.error().find("files.cassette"), std::string::npos) << v.error();
    s = load("[files]\ncassette = 1\n");
    ASSERT_FALSE(s);
    EXPECT_NE(s.error().find("files.cassette"), std::string::npos) << s.error();
}

}  // namespace
}  // namespace fins::finsd
