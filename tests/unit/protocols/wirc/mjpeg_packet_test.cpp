#include "wirc/mjpeg_packet.h"

#include <gtest/gtest.h>

#include <vector>

namespace wircam::wirc {
namespace {

using Bytes = std::vector<uint8_t>;

Bytes datagram(uint32_t version, uint32_t frame, uint32_t offset, uint32_t length,
               const Bytes& payload) {
  Bytes out;
  writeMjpegHeader({version, frame, offset, length}, out);
  out.insert(out.end(), payload.begin(), payload.end());
  return out;
}

TEST(MjpegPacket, ParsesTheBigEndianHeader) {
  Bytes bytes = {0x00, 0x01, 0x55, 0x03, 0x00, 0x00, 0x01, 0x02, 0x00,
                 0x00, 0x00, 0x10, 0x00, 0x00, 0x00, 0x02, 0xAB, 0xCD};
  auto packet = parseMjpegPacket(bytes);
  ASSERT_TRUE(packet.has_value());
  EXPECT_EQ(packet->header.frameNumber, 0x102u);
  EXPECT_EQ(packet->header.offset, 0x10u);
  EXPECT_EQ(packet->header.length, 2u);
  EXPECT_TRUE(packet->header.lastPacket());
  EXPECT_EQ(packet->payload.size(), 2u);
  EXPECT_EQ(packet->payload[1], 0xCD);
}

TEST(MjpegPacket, IgnoresTheReservedVersionBits) {
  auto packet = parseMjpegPacket(datagram(0xFFFE5503, 1, 0, 1, {0xFF}));
  ASSERT_TRUE(packet.has_value());
  EXPECT_FALSE(packet->header.lastPacket());
  packet = parseMjpegPacket(datagram(0xFFFF5503, 1, 0, 1, {0xFF}));
  ASSERT_TRUE(packet.has_value());
  EXPECT_TRUE(packet->header.lastPacket());
}

TEST(MjpegPacket, RejectsAnotherVersion) {
  EXPECT_EQ(parseMjpegPacket(datagram(0x00015504, 1, 0, 1, {0})).error(), PacketError::BadVersion);
  EXPECT_EQ(parseMjpegPacket(datagram(0x03550000, 1, 0, 1, {0})).error(), PacketError::BadVersion);
}

TEST(MjpegPacket, TreatsAVersionOnlyDatagramAsKeepalive) {
  EXPECT_EQ(parseMjpegPacket(Bytes{0x00, 0x00, 0x55, 0x03}).error(), PacketError::Keepalive);
}

TEST(MjpegPacket, RejectsDatagramsShorterThanTheHeader) {
  Bytes full = datagram(kMjpegVersion, 1, 0, 0, {});
  for (size_t size : {0, 1, 3, 5, 15})
    EXPECT_EQ(parseMjpegPacket(std::span(full).first(size)).error(), PacketError::TooShort) << size;
}

TEST(MjpegPacket, RejectsALengthLargerThanTheDatagram) {
  EXPECT_EQ(parseMjpegPacket(datagram(kMjpegVersion, 1, 0, 3, {1, 2})).error(),
            PacketError::BadLength);
  EXPECT_EQ(parseMjpegPacket(datagram(kMjpegVersion, 1, 0, 0xFFFFFFFF, {1})).error(),
            PacketError::BadLength);
}

TEST(MjpegPacket, UsesOnlyLengthBytesOfALongerDatagram) {
  auto packet = parseMjpegPacket(datagram(kMjpegVersion, 1, 0, 1, {7, 8, 9}));
  ASSERT_TRUE(packet.has_value());
  EXPECT_EQ(packet->payload.size(), 1u);
}

TEST(MjpegPacket, PacketizeCutsAtTheFragmentSizeAndFlagsTheLast) {
  Bytes frame(2500);
  for (size_t i = 0; i < frame.size(); ++i) frame[i] = static_cast<uint8_t>(i);
  auto packets = packetizeFrame(frame, 9, 1000);
  ASSERT_EQ(packets.size(), 3u);
  Bytes joined;
  for (size_t i = 0; i < packets.size(); ++i) {
    auto packet = parseMjpegPacket(packets[i]);
    ASSERT_TRUE(packet.has_value());
    EXPECT_EQ(packet->header.frameNumber, 9u);
    EXPECT_EQ(packet->header.offset, i * 1000);
    EXPECT_EQ(packet->header.lastPacket(), i == 2);
    joined.insert(joined.end(), packet->payload.begin(), packet->payload.end());
  }
  EXPECT_EQ(joined, frame);
}

}  // namespace
}  // namespace wircam::wirc
