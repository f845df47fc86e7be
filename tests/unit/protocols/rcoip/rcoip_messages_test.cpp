#include "rcoip/rcoip_messages.h"

#include <gtest/gtest.h>

namespace wircam::rcoip {
namespace {

using Bytes = std::vector<uint8_t>;

TEST(RcoipMessages, EncodesACommandAsVersionThenChannelBytes) {
  EXPECT_EQ(encode(Command{{128, 0, 255}}), (Bytes{0x01, 0x80, 0x00, 0xFF}));
  EXPECT_EQ(encode(Command{}), (Bytes{0x01}));
}

TEST(RcoipMessages, DecodesCommandsOfAnyChannelCount) {
  auto command = decodeCommand(Bytes{0x01, 0x10, 0x20});
  ASSERT_TRUE(command);
  EXPECT_EQ(command->channels, (Bytes{0x10, 0x20}));
  EXPECT_TRUE(decodeCommand(Bytes{0x01}));  // 0 channels is allowed
}

TEST(RcoipMessages, EncodesAndDecodesBothReplyVariants) {
  EXPECT_EQ(encode(Reply{.rssi = 200, .battery = 255}), (Bytes{0x01, 0xC8, 0xFF}));
  EXPECT_EQ(encode(Reply{.battery = 17}), (Bytes{0x01, 0x11}));
  auto full = decodeReply(Bytes{0x01, 0xC8, 0xFF});
  ASSERT_TRUE(full);
  EXPECT_EQ(full->rssi, 200);
  EXPECT_DOUBLE_EQ(full->batteryVolts(), 15.0);
  auto short_ = decodeReply(Bytes{0x01, 0x11});
  ASSERT_TRUE(short_);
  EXPECT_FALSE(short_->rssi);
  EXPECT_DOUBLE_EQ(short_->batteryVolts(), 1.0);
}

TEST(RcoipMessages, RefusesEmptyWrongVersionAndWrongLength) {
  EXPECT_EQ(decodeCommand(Bytes{}).error(), DecodeError::Empty);
  EXPECT_EQ(decodeCommand(Bytes{0x02, 0x80}).error(), DecodeError::WrongVersion);
  EXPECT_EQ(decodeCommand(Bytes(300, 0x01)).error(), DecodeError::TooLong);
  EXPECT_EQ(decodeReply(Bytes{0x01}).error(), DecodeError::WrongLength);
  EXPECT_EQ(decodeReply(Bytes{0x01, 1, 2, 3}).error(), DecodeError::WrongLength);
  EXPECT_EQ(decodeReply(Bytes{0x00, 1, 2}).error(), DecodeError::WrongVersion);
}

}  // namespace
}  // namespace wircam::rcoip
