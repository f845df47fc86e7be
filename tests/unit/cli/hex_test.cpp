// wirc-cli's hex input.
#include "hex.h"

#include <gtest/gtest.h>

namespace wircam::cli {
namespace {

TEST(Hex, ReadsBytesWithOrWithoutSeparators) {
  std::vector<uint8_t> expected = {0xAA, 0xBB, 0x01};
  EXPECT_EQ(*parseHex("aabb01"), expected);
  EXPECT_EQ(*parseHex("AA BB 01\n"), expected);
  EXPECT_EQ(*parseHex("aa:bb:01"), expected);
  EXPECT_EQ(*parseHex("aa,bb,01"), expected);
  EXPECT_TRUE(parseHex("")->empty());
}

TEST(Hex, RefusesOddDigitsAndOtherCharacters) {
  EXPECT_EQ(parseHex("abc").error(), "an odd number of hex digits");
  EXPECT_EQ(parseHex("zz").error(), "not hex: 'z'");
}

}  // namespace
}  // namespace wircam::cli
