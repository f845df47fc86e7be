// StreamInbox on a real loopback socket: a frame's time is when its packet
// reached the machine (the kernel's stamp), not when the thread read it.
#include "wirc/stream_inbox.h"

#include <gtest/gtest.h>

#include <thread>

#include "common/socket.h"

namespace wircam::wirc {
namespace {

using std::chrono::milliseconds;

TEST(StreamInbox, AFramesTimeIsItsArrivalNotWhenItWasRead) {
  StreamInbox inbox;
  ASSERT_EQ(inbox.open(0, {}), std::nullopt);
  auto sender = bindUdp(SocketAddress::loopback(0));
  ASSERT_TRUE(sender);
  inbox.receiver().follow(SocketAddress::loopback(1984), 1);
  std::vector<uint8_t> jpeg = {0xFF, 0xD8, 0xFF, 0xD9};
  auto datagram = packetizeFrame(jpeg, 1, 1400).front();
  auto sent = StreamInbox::Clock::now();
  ASSERT_TRUE(sendDatagram(sender->get(), SocketAddress::loopback(inbox.port()), datagram));
  // A busy machine lets the reader run only later.
  std::this_thread::sleep_for(milliseconds(200));
  ASSERT_EQ(inbox.wait(StreamInbox::Clock::now() + milliseconds(1000)), StreamInbox::Wake::Frame);
  auto frame = inbox.takeFrame();
  ASSERT_TRUE(frame);
  EXPECT_LT(frame->firstPacketTime - sent, milliseconds(100));
  EXPECT_GE(frame->firstPacketTime, sent - milliseconds(1));
}

}  // namespace
}  // namespace wircam::wirc
