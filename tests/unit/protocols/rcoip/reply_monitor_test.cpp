// The RCOIP link's liveness with a fake clock: live on the receiver's reply,
// lost after the fail interval of silence, live again on the next reply;
// strangers and malformed replies counted, never taken.
#include "rcoip/reply_monitor.h"

#include <gtest/gtest.h>

namespace {

using namespace wircam;
using namespace wircam::rcoip;
using std::chrono::milliseconds;
using Clock = ReplyMonitor::Clock;

const SocketAddress kReceiver = *SocketAddress::resolve("127.0.0.1", 9048);

template <typename Event>
const Event* find(const std::vector<link::LinkEvent>& events) {
  for (const auto& event : events)
    if (const auto* found = std::get_if<Event>(&event)) return found;
  return nullptr;
}

class ReplyMonitorTest : public ::testing::Test {
 protected:
  std::vector<link::LinkEvent> replyAt(milliseconds offset, uint8_t battery = 200) {
    return monitor_.onDatagram(kReceiver, encode(Reply{.rssi = 40, .battery = battery}),
                               start_ + offset);
  }
  std::vector<link::LinkEvent> deadlineAt(milliseconds offset) {
    return monitor_.onDeadline(start_ + offset);
  }

  Clock::time_point start_ = Clock::time_point(std::chrono::hours(1));
  ReplyMonitor monitor_{kReceiver, milliseconds(2000)};
};

TEST_F(ReplyMonitorTest, TheFirstReplyMakesTheLinkLiveWithItsTelemetry) {
  EXPECT_EQ(monitor_.status().state, link::LinkState::Connecting);
  EXPECT_EQ(monitor_.nextDeadline(), std::nullopt);
  auto events = replyAt(milliseconds(100), 255);
  ASSERT_NE(find<link::StateChanged>(events), nullptr);
  EXPECT_EQ(find<link::StateChanged>(events)->reason, "replies from 127.0.0.1:9048");
  ASSERT_NE(find<link::TelemetryReceived>(events), nullptr);
  EXPECT_DOUBLE_EQ(*find<link::TelemetryReceived>(events)->telemetry.batteryVolts, 15.0);
  EXPECT_EQ(*find<link::TelemetryReceived>(events)->telemetry.rssi, 40);
  EXPECT_EQ(monitor_.status().logins, 1u);
  EXPECT_EQ(*monitor_.nextDeadline(), start_ + milliseconds(2100));
}

TEST_F(ReplyMonitorTest, TheFailIntervalWithoutAReplyLosesTheLinkAndAReplyBringsItBack) {
  replyAt(milliseconds(0));
  replyAt(milliseconds(1000));  // each reply moves the deadline
  EXPECT_TRUE(deadlineAt(milliseconds(2999)).empty());
  auto lost = deadlineAt(milliseconds(3000));
  ASSERT_NE(find<link::StateChanged>(lost), nullptr);
  EXPECT_EQ(find<link::StateChanged>(lost)->state, link::LinkState::Lost);
  EXPECT_NE(find<link::StateChanged>(lost)->reason.find("no reply from 127.0.0.1:9048 for 2000 ms"),
            std::string::npos);
  EXPECT_EQ(monitor_.nextDeadline(), std::nullopt);
  EXPECT_TRUE(deadlineAt(milliseconds(9000)).empty());  // lost once

  auto again = replyAt(milliseconds(9000));
  ASSERT_NE(find<link::StateChanged>(again), nullptr);
  EXPECT_EQ(find<link::StateChanged>(again)->reason, "replies again from 127.0.0.1:9048");
  EXPECT_EQ(monitor_.status().logins, 2u);
}

TEST_F(ReplyMonitorTest, StrangersAndMalformedRepliesAreCountedNeverTaken) {
  auto stranger = *SocketAddress::resolve("127.0.0.1", 9049);
  EXPECT_TRUE(monitor_.onDatagram(stranger, encode(Reply{.battery = 1}), start_).empty());
  EXPECT_EQ(monitor_.status().foreignDatagrams, 1u);
  std::vector<uint8_t> junk(40, 0xEE);
  EXPECT_TRUE(monitor_.onDatagram(kReceiver, junk, start_).empty());
  EXPECT_TRUE(monitor_.onDatagram(kReceiver, junk, start_).empty());
  EXPECT_EQ(monitor_.status().inputRejected, 2u);
  EXPECT_EQ(monitor_.status().state, link::LinkState::Connecting);
  auto summary = monitor_.rejectSummary(start_ + milliseconds(1000));
  ASSERT_TRUE(summary.has_value());
  EXPECT_EQ(std::get<link::InputRejected>(*summary).count, 2u);
  EXPECT_FALSE(monitor_.rejectSummary(start_ + milliseconds(1500)).has_value());
}

}  // namespace
