#include "wirc/crc16.h"

#include <gtest/gtest.h>

#include <string_view>
#include <vector>

namespace wircam::wirc {
namespace {

TEST(Crc16Xmodem, MatchesTheStandardCheckValue) {
  std::string_view text = "123456789";
  std::vector<uint8_t> bytes(text.begin(), text.end());
  EXPECT_EQ(crc16Xmodem(bytes), 0x31C3);
}

TEST(Crc16Xmodem, MatchesTheSpecExampleOverCmdLenAndBody) {
  std::vector<uint8_t> covered = {0x1A, 0x04, 0x01, 0x01, 0x01, 0x00};
  EXPECT_EQ(crc16Xmodem(covered), 0x6735);
}

TEST(Crc16Xmodem, CanBeComputedInPieces) {
  std::vector<uint8_t> a = {0x1A, 0x04, 0x01};
  std::vector<uint8_t> b = {0x01, 0x01, 0x00};
  EXPECT_EQ(crc16Xmodem(b, crc16Xmodem(a)), 0x6735);
}

}  // namespace
}  // namespace wircam::wirc
