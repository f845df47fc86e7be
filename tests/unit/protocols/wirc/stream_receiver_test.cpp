// StreamReceiver with a fake clock: who may feed the stream.
#include "wirc/stream_receiver.h"

#include <gtest/gtest.h>

namespace wircam::wirc {
namespace {

using std::chrono::milliseconds;
using Clock = StreamReceiver::Clock;

// A one-packet JPEG frame (SOI ... EOI) as a datagram.
std::vector<uint8_t> framePacket(uint32_t number) {
  std::vector<uint8_t> jpeg = {0xFF, 0xD8, 0xFF, 0xD9};
  return packetizeFrame(jpeg, number, 1400).front();
}

class StreamReceiverTest : public ::testing::Test {
 protected:
  StreamReceiver receiver;
  SocketAddress device = SocketAddress::loopback(1984);
  Clock::time_point t0 = Clock::now();
  int frames = 0;
  void push(const SocketAddress& from, const std::vector<uint8_t>& datagram, int ms) {
    receiver.push(from, datagram, t0 + milliseconds(ms), [&](AssembledFrame&&) { ++frames; });
  }
  void SetUp() override { receiver.follow(device, 1); }
};

TEST_F(StreamReceiverTest, IgnoresPacketsFromAnotherHost) {
  push(*SocketAddress::resolve("127.0.0.2", 5000), framePacket(1), 0);
  EXPECT_EQ(frames, 0);
  EXPECT_EQ(receiver.stats().packetsForeign, 1u);
}

TEST_F(StreamReceiverTest, AJunkFloodCannotClaimTheStream) {
  std::vector<uint8_t> junk(100, 0x42);
  for (int i = 0; i < 1000; ++i) push(device.withPort(6000), junk, 0);
  EXPECT_FALSE(receiver.pinnedPort().has_value());
  push(device.withPort(7000), framePacket(1), 1);
  EXPECT_EQ(frames, 1);
  EXPECT_EQ(receiver.pinnedPort(), 7000);
}

TEST_F(StreamReceiverTest, PinsTheFirstValidSenderAndIgnoresOtherPortsWhileItSends) {
  push(device.withPort(7000), framePacket(1), 0);
  push(device.withPort(7001), framePacket(2), 10);
  EXPECT_EQ(frames, 1);
  EXPECT_EQ(receiver.stats().packetsForeign, 1u);
}

TEST_F(StreamReceiverTest, FollowsANewPortWhenThePinnedOneWentQuiet) {
  push(device.withPort(7000), framePacket(1), 0);
  push(device.withPort(7001), framePacket(1), 999);
  EXPECT_EQ(frames, 1);
  push(device.withPort(7001), framePacket(1), 1000 + 1);
  EXPECT_EQ(frames, 2);
  EXPECT_EQ(receiver.pinnedPort(), 7001);
}

TEST_F(StreamReceiverTest, ANewLoginForgetsThePinnedPort) {
  push(device.withPort(7000), framePacket(5), 0);
  receiver.follow(device, 2);
  push(device.withPort(7001), framePacket(1), 10);
  EXPECT_EQ(frames, 2);
}

}  // namespace
}  // namespace wircam::wirc
