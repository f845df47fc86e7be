#include "link/channel_byte_map.h"

#include <gtest/gtest.h>

namespace wircam::link {
namespace {

TEST(ChannelByteMap, MapsThePulseRangeLinearlyOntoBytes) {
  ChannelByteMap map;
  EXPECT_EQ(map.toByte(1, 800), 0);
  EXPECT_EQ(map.toByte(1, 2200), 255);
  EXPECT_EQ(map.toByte(1, 1500), 128);  // 127.5 rounds up
  EXPECT_EQ(map.toByte(1, 1150), 64);   // a quarter of the way: 63.75
  EXPECT_EQ(map.toPulse(1, 0), 800);
  EXPECT_EQ(map.toPulse(1, 255), 2200);
  EXPECT_EQ(map.toPulse(1, 128), 1503);
  EXPECT_EQ(map.toPulse(1, 127), 1497);
}

TEST(ChannelByteMap, ClampsPulsesOutsideTheRange) {
  ChannelByteMap map;
  EXPECT_EQ(map.toByte(2, 0), 0);
  EXPECT_EQ(map.toByte(2, 65535), 255);
}

TEST(ChannelByteMap, RoundTripsEveryByte) {
  ChannelByteMap map;
  for (int byte = 0; byte < 256; ++byte)
    EXPECT_EQ(map.toByte(3, map.toPulse(3, static_cast<uint8_t>(byte))), byte);
}

TEST(ChannelByteMap, HonoursAChannelsOwnRangeAndReversal) {
  auto map = ChannelByteMap::parse("2:1000-2000,3:2200-800");
  ASSERT_TRUE(map) << map.error();
  EXPECT_EQ(map->toByte(2, 1000), 0);
  EXPECT_EQ(map->toByte(2, 900), 0);
  EXPECT_EQ(map->toByte(2, 2000), 255);
  EXPECT_EQ(map->toByte(3, 800), 255);
  EXPECT_EQ(map->toByte(3, 2200), 0);
  EXPECT_EQ(map->toByte(1, 800), 0);  // untouched
  EXPECT_EQ(map->toString(), "2:1000-2000,3:2200-800");
}

TEST(ChannelByteMap, RefusesMalformedOverrides) {
  for (const char* bad : {"2", "2:1000", "0:1000-2000", "13:1000-2000", "2:700-2000", "2:1000-2300",
                          "2:1500-1500", "2:1000-2000x"})
    EXPECT_FALSE(ChannelByteMap::parse(bad)) << bad;
}

}  // namespace
}  // namespace wircam::link
