#include "btemp/btemp_messages.h"

#include <gtest/gtest.h>

namespace wircam::btemp {
namespace {

using Bytes = std::vector<uint8_t>;

// protocols/NOTES.md's worked example.
const Bytes kPing = {0xef, 0x36, 0x4e, 0x77, 0xe4, 0x00, 0x00, 0x08, 0x50, 0x49, 0x4e, 0x47};

TEST(BtempMessages, EncodesTheNotesPingByteForByte) { EXPECT_EQ(encode(Ping{}), kPing); }

TEST(BtempMessages, DecodesTheNotesPing) {
  auto message = decode(kPing);
  ASSERT_TRUE(message);
  EXPECT_EQ(std::get<Ping>(*message), Ping{});
}

TEST(BtempMessages, HashesTheFirstTwelveBytesWithBteInPlaceOfTheHash) {
  EXPECT_EQ(syncHash(kPing), 0x364e77u);
}

TEST(BtempMessages, EncodesCtrlAsImpulsesThenFourThrottleBytes) {
  auto bytes = encode(Ctrl{.impulse1 = 0x00000401, .impulse2 = 2, .throttle = {128, 0, 255, 7}});
  ASSERT_EQ(bytes.size(), 4u + 8u + 12u);
  EXPECT_EQ(Bytes(bytes.begin() + 4, bytes.begin() + 12),
            (Bytes{0xe4, 0x00, 0x00, 0x14, 'C', 'T', 'R', 'L'}));
  EXPECT_EQ(Bytes(bytes.begin() + 12, bytes.end()),
            (Bytes{0, 0, 0x04, 0x01, 0, 0, 0, 2, 128, 0, 255, 7}));
  EXPECT_EQ(syncHash(std::span(bytes).first(12)),
            uint32_t{bytes[1]} << 16 | uint32_t{bytes[2]} << 8 | bytes[3]);
}

TEST(BtempMessages, RoundTripsEveryMessage) {
  Guid a{}, b{};
  for (size_t i = 0; i < a.size(); ++i) a[i] = static_cast<uint8_t>(i), b[i] = 0xF0;
  std::vector<Message> messages = {
      Ping{},
      Ping{NodeInfo{a, nodeFlags(NodeType::Controller)}},
      Piak{{a, nodeFlags(NodeType::Robot)}},
      Rctr{.node = a, .auth = b, .authTag = 3, .formatTag = 4},
      Rcak{},
      Ctrl{.impulse1 = 1, .impulse2 = 2, .throttle = {1, 2, 3, 4}},
      Idle{},
      Pins{.inputs = 1, .outputs = 2, .pdmMask = 0x05, .pdmActive = 0x04, .duty = {10, 20}},
  };
  for (const auto& message : messages) {
    auto decoded = decode(encode(message));
    ASSERT_TRUE(decoded) << messageName(message) << ": " << decodeErrorName(decoded.error());
    EXPECT_EQ(*decoded, message) << messageName(message);
  }
}

TEST(BtempMessages, ReadsNodeFlags) {
  EXPECT_EQ(nodeTypeOf(0x42), NodeType::Robot);
  EXPECT_FALSE(wantsResponse(0x42));
  EXPECT_TRUE(wantsResponse(0x02));
}

TEST(BtempMessages, RecognisesVideoSegmentsWithoutDecodingThem) {
  Bytes segment = encode(VideoSegment{"VS1G"});
  segment.insert(segment.end(), {0xe3, 0, 0, 6, 'S', 'H'});  // whatever follows is opaque
  auto decoded = decode(segment);
  ASSERT_TRUE(decoded);
  EXPECT_EQ(std::get<VideoSegment>(*decoded).fourcc, "VS1G");
}

Bytes withHash(Bytes bytes, size_t covered) {
  uint32_t h = syncHash(std::span(bytes).first(covered));
  bytes[1] = static_cast<uint8_t>(h >> 16), bytes[2] = static_cast<uint8_t>(h >> 8);
  bytes[3] = static_cast<uint8_t>(h);
  return bytes;
}

TEST(BtempMessages, RefusesBrokenDatagramsByName) {
  Bytes badHash = kPing;
  badHash[3] ^= 1;
  Bytes badSync = kPing;
  badSync[0] = 0xEE;
  Bytes unknownTlv = withHash({0xef, 0, 0, 0, 0xe1, 0, 0, 8, 'P', 'I', 'N', 'G'}, 12);
  Bytes longTlv = withHash({0xef, 0, 0, 0, 0xe4, 0, 0, 9, 'P', 'I', 'N', 'G'}, 12);
  Bytes shortTlv = withHash({0xef, 0, 0, 0, 0xe4, 0, 0, 7, 'P', 'I', 'N', 'G'}, 12);
  Bytes unknownName = withHash({0xef, 0, 0, 0, 0xe4, 0, 0, 8, 'P', 'O', 'N', 'G'}, 12);
  Bytes shortBody = withHash({0xef, 0, 0, 0, 0xe4, 0, 0, 9, 'R', 'C', 'T', 'R', 1}, 12);
  Bytes twocc = withHash({0xef, 0, 0, 0, 0xe5, 4, 'S', 'H'}, 8);
  EXPECT_EQ(decode(Bytes{0xef, 1}).error(), DecodeError::TooShort);
  EXPECT_EQ(decode(Bytes(kPing.begin(), kPing.end() - 1)).error(), DecodeError::TooShort);
  EXPECT_EQ(decode(badHash).error(), DecodeError::BadHash);
  EXPECT_EQ(decode(badSync).error(), DecodeError::BadSync);
  EXPECT_EQ(decode(unknownTlv).error(), DecodeError::UnknownTlv);
  EXPECT_EQ(decode(longTlv).error(), DecodeError::BadTlvLength);
  EXPECT_EQ(decode(shortTlv).error(), DecodeError::BadTlvLength);
  EXPECT_EQ(decode(unknownName).error(), DecodeError::UnknownMessage);
  EXPECT_EQ(decode(shortBody).error(), DecodeError::BadBody);
  EXPECT_EQ(decode(twocc).error(), DecodeError::UnknownMessage);
}

TEST(BtempMessages, RefusesPinsWithoutADutyBytePerPdmPin) {
  Bytes pins = encode(Pins{.pdmMask = 0x3, .duty = {1, 2}});
  pins.pop_back();
  pins[7] -= 1;  // keep the TLV length truthful: only the body is short
  EXPECT_EQ(decode(withHash(pins, 12)).error(), DecodeError::BadBody);
}

}  // namespace
}  // namespace wircam::btemp
