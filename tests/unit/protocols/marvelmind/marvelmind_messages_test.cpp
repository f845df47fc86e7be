#include "marvelmind/marvelmind_messages.h"

#include <gtest/gtest.h>

#include <string_view>

namespace wircam::marvelmind {
namespace {

using Bytes = std::vector<uint8_t>;

// A cm reply of beacon 5 at t = 100 (1/64 s), x 1.23 m, y -0.5 m, z 0.25 m,
// laid out by hand from the protocol text's table.
Bytes handMadeReply() {
  Bytes reply = {0x05, 0x47, 0x01, 0x00, 0x10,      // addr, type, code, size
                 0x64, 0x00, 0x00, 0x00,            // timestamp 100
                 0x7B, 0x00,                        // x 123 cm
                 0xCE, 0xFF,                        // y -50 cm
                 0x19, 0x00,                        // z 25 cm
                 0,    0,    0,    0,    0,    0};  // reserved
  uint16_t crc = crc16Modbus(reply);
  reply.push_back(static_cast<uint8_t>(crc & 0xFF));
  reply.push_back(static_cast<uint8_t>(crc >> 8));
  return reply;
}

TEST(MarvelmindMessages, Crc16ModbusMatchesTheStandardCheckValue) {
  std::string_view check = "123456789";
  EXPECT_EQ(crc16Modbus({reinterpret_cast<const uint8_t*>(check.data()), check.size()}), 0x4B37);
}

TEST(MarvelmindMessages, EncodesTheRequestOfTheNotes) {
  // NOTES.md: "A valid request: 30 47 01 00 04 00 00 10 75 36".
  Bytes expected = {0x30, 0x47, 0x01, 0x00, 0x04, 0x00, 0x00, 0x10, 0x75, 0x36};
  EXPECT_EQ(encode(Request{.beacon = 0x30}), expected);
  // Over the whole frame the CRC comes out 0, as the appendix says.
  EXPECT_EQ(crc16Modbus(expected), 0);
  auto decoded = decodeRequest(expected);
  ASSERT_TRUE(decoded);
  EXPECT_EQ(decoded->beacon, 0x30);
  EXPECT_EQ(decoded->resolution, Resolution::kCentimetres);
}

TEST(MarvelmindMessages, RequestsMayCarryAZeroCrcButNotAWrongOne) {
  Bytes zero = encode(Request{.beacon = 7, .resolution = Resolution::kMillimetres}, true);
  EXPECT_EQ(zero, (Bytes{0x07, 0x47, 0x11, 0x00, 0x04, 0x00, 0x00, 0x16, 0x00, 0x00}));
  EXPECT_TRUE(decodeRequest(zero));
  Bytes wrong = encode(Request{.beacon = 7});
  wrong[8] ^= 1;
  EXPECT_EQ(decodeRequest(wrong).error(), DecodeError::kBadCrc);
}

TEST(MarvelmindMessages, DecodesACentimetreReplyLaidOutByHand) {
  auto reply = decodeReply(handMadeReply());
  ASSERT_TRUE(reply);
  EXPECT_EQ(reply->beacon, 5);
  EXPECT_EQ(reply->timestamp, 100u);
  EXPECT_EQ(reply->xMm, 1230);
  EXPECT_EQ(reply->yMm, -500);
  EXPECT_EQ(reply->zMm, 250);
  EXPECT_EQ(encode(*reply), handMadeReply());
}

TEST(MarvelmindMessages, MillimetreRepliesRoundTrip) {
  Reply reply{.beacon = 9,
              .resolution = Resolution::kMillimetres,
              .timestamp = 123456,
              .xMm = -40000,
              .yMm = 1234567,
              .zMm = 1,
              .flags = 0x02,
              .angle = 900};
  Bytes bytes = encode(reply);
  ASSERT_EQ(bytes.size(), 29u);
  EXPECT_EQ(bytes[4], 0x16);
  EXPECT_EQ(bytes[22], 9);  // the address again, inside the data
  auto decoded = decodeReply(bytes);
  ASSERT_TRUE(decoded);
  EXPECT_EQ(*decoded, reply);
}

TEST(MarvelmindMessages, CentimetreRepliesRoundAndClamp) {
  Reply reply{.beacon = 1, .xMm = 1234, .yMm = -1236, .zMm = 400000};
  auto decoded = decodeReply(encode(reply));
  ASSERT_TRUE(decoded);
  EXPECT_EQ(decoded->xMm, 1230);
  EXPECT_EQ(decoded->yMm, -1240);
  EXPECT_EQ(decoded->zMm, 327670);  // int16 cm at most
}

TEST(MarvelmindMessages, RefusesEveryMalformedReply) {
  Bytes good = handMadeReply();
  auto errorOf = [](Bytes bytes) { return decodeReply(bytes).error(); };
  EXPECT_EQ(errorOf({}), DecodeError::kWrongLength);
  EXPECT_EQ(errorOf(Bytes(good.begin(), good.end() - 1)), DecodeError::kWrongLength);
  Bytes longer = good;
  longer.push_back(0);
  EXPECT_EQ(errorOf(longer), DecodeError::kWrongLength);
  Bytes badCrc = good;
  badCrc[10] ^= 0x40;  // x changes, the CRC no longer checks
  EXPECT_EQ(errorOf(badCrc), DecodeError::kBadCrc);
  Bytes type = good;
  type[1] = 0x48;
  EXPECT_EQ(errorOf(type), DecodeError::kWrongType);
  Bytes code = good;
  code[2] = 0x02;  // the stationary beacons' list: not a position
  EXPECT_EQ(errorOf(code), DecodeError::kUnknownCode);
  Bytes size = good;
  size[4] = 0x11;
  EXPECT_EQ(errorOf(size), DecodeError::kWrongDataSize);
}

TEST(MarvelmindMessages, TimestampUnits) {
  EXPECT_DOUBLE_EQ(secondsOf(128, TimestampUnit::kSixtyFourths), 2.0);
  EXPECT_DOUBLE_EQ(secondsOf(1500, TimestampUnit::kMilliseconds), 1.5);
  EXPECT_EQ(timestampOf(2.0, TimestampUnit::kSixtyFourths), 128u);
  EXPECT_EQ(timestampOf(1.5, TimestampUnit::kMilliseconds), 1500u);
}

}  // namespace
}  // namespace wircam::marvelmind
