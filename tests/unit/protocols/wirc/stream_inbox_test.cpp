// StreamInbox: a frame's time is when its packet reached the machine (the
// kernel's stamp), not when the thread read it.
#include "wirc/stream_inbox.h"

#include <gtest/gtest.h>

#include <array>
#include <cstring>

#include "common/socket.h"

namespace wircam::wirc {
namespace {

using std::chrono::milliseconds;
using Clock = StreamInbox::Clock;

// A received message's control data holding the kernel's stamp `stamp`.
struct StampedMessage {
  std::array<char, CMSG_SPACE(sizeof(timespec))> control{};
  msghdr message{};
  explicit StampedMessage(std::optional<timespec> stamp) {
    message.msg_control = control.data();
    message.msg_controllen = stamp ? control.size() : 0;
    if (!stamp) return;
    cmsghdr* c = CMSG_FIRSTHDR(&message);
    c->cmsg_level = SOL_SOCKET;
    c->cmsg_type = SCM_TIMESTAMPNS;
    c->cmsg_len = CMSG_LEN(sizeof(timespec));
    std::memcpy(CMSG_DATA(c), &*stamp, sizeof(timespec));
  }
};

TEST(StreamInbox, AReadLateDatagramKeepsTheTimeTheKernelStampedOnIt) {
  auto now = Clock::time_point() + std::chrono::hours(1);
  timespec wallNow{1764200000, 300000000};
  // Read 200 ms after it arrived (a busy machine).
  StampedMessage late(timespec{1764200000, 100000000});
  EXPECT_EQ(StreamInbox::arrivalOf(late.message, now, wallNow), now - milliseconds(200));
  // No stamp, or one the wall clock's step made nonsense of: read now.
  StampedMessage unstamped(std::nullopt);
  EXPECT_EQ(StreamInbox::arrivalOf(unstamped.message, now, wallNow), now);
  StampedMessage future(timespec{1764200001, 0});
  EXPECT_EQ(StreamInbox::arrivalOf(future.message, now, wallNow), now);
  StampedMessage ancient(timespec{1764100000, 0});
  EXPECT_EQ(StreamInbox::arrivalOf(ancient.message, now, wallNow), now);
}

TEST(StreamInbox, ASocketsFramesCarryTheKernelsArrivalTime) {
  StreamInbox inbox;
  ASSERT_EQ(inbox.open(0, {}), std::nullopt);
  auto sender = bindUdp(SocketAddress::loopback(0));
  ASSERT_TRUE(sender);
  inbox.receiver().follow(SocketAddress::loopback(1984), 1);
  std::vector<uint8_t> jpeg = {0xFF, 0xD8, 0xFF, 0xD9};
  auto datagram = packetizeFrame(jpeg, 1, 1400).front();
  auto sent = Clock::now();
  ASSERT_TRUE(sendDatagram(sender->get(), SocketAddress::loopback(inbox.port()), datagram));
  ASSERT_EQ(inbox.wait(Clock::now() + milliseconds(1000)), StreamInbox::Wake::Frame);
  auto read = Clock::now();
  auto frame = inbox.takeFrame();
  ASSERT_TRUE(frame);
  // Between the send and the read (stamped, not taken as the read's time,
  // as the test above shows).
  EXPECT_GE(frame->firstPacketTime, sent - milliseconds(1));
  EXPECT_LE(frame->firstPacketTime, read);
}

TEST(StreamInbox, TheLoginIsHeardBeforeTheFirstFrameItBrought) {
  // The device streams the moment STST arrives, which the login sends right
  // after telling the inbox the link changed. Both are waiting when the
  // streaming thread wakes: the link first, so that the caller follows the
  // device before its datagrams are read. (Read first, the first frame came
  // from a device not yet followed: dropped as foreign. Replay.* saw it on
  // a loaded machine: the recording lacked its first frame.)
  StreamInbox inbox;
  ASSERT_EQ(inbox.open(0, {}), std::nullopt);
  auto device = bindUdp(SocketAddress::loopback(0));
  ASSERT_TRUE(device);
  inbox.linkChanged();
  std::vector<uint8_t> jpeg = {0xFF, 0xD8, 0xFF, 0xD9};
  ASSERT_TRUE(sendDatagram(device->get(), SocketAddress::loopback(inbox.port()),
                           packetizeFrame(jpeg, 1, 1400).front()));
  ASSERT_EQ(inbox.wait(Clock::now() + milliseconds(1000)), StreamInbox::Wake::LinkChanged);
  inbox.receiver().follow(SocketAddress::loopback(1984), 1);
  ASSERT_EQ(inbox.wait(Clock::now() + milliseconds(1000)), StreamInbox::Wake::Frame);
  EXPECT_TRUE(inbox.takeFrame());
  EXPECT_EQ(inbox.receiver().stats().packetsForeign, 0u);
}

}  // namespace
}  // namespace wircam::wirc
