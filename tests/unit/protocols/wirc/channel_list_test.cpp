// Channel lists as users write them.
#include "wirc/channel_list.h"

#include <gtest/gtest.h>

namespace wircam::wirc {
namespace {

TEST(ChannelList, OneValueIsForEveryChannel) {
  auto channels = parseChannelList("20000");
  ASSERT_TRUE(channels.has_value()) << channels.error();
  for (auto value : *channels) EXPECT_EQ(value, 20000);
}

TEST(ChannelList, TwelveValuesAreOnePerChannel) {
  auto channels = parseChannelList("800,900,1000,1100,1200,1300,1400,1500,1600,1700,1800,1900");
  ASSERT_TRUE(channels.has_value()) << channels.error();
  EXPECT_EQ((*channels)[0], 800);
  EXPECT_EQ((*channels)[11], 1900);
  EXPECT_EQ(formatChannelList(*channels),
            "800,900,1000,1100,1200,1300,1400,1500,1600,1700,1800,1900");
}

TEST(ChannelList, AnythingElseIsRefusedSayingWhy) {
  for (const char* bad : {"", "1500,", "1500,1500", "abc", "70000", "-1", "1500 "}) {
    auto channels = parseChannelList(bad);
    EXPECT_FALSE(channels.has_value()) << bad;
  }
  EXPECT_NE(parseChannelList("1500,1500").error().find("give 1"), std::string::npos);
}

}  // namespace
}  // namespace wircam::wirc
