// The dashboard's replies as positions, with a fake clock: a new position
// per new measurement, repeats and strangers counted, a beacon stale after
// staleAfter without news (with why), back with its next position.
#include "marvelmind/beacon_tracker.h"

#include <gtest/gtest.h>

namespace {

using namespace wircam;
using namespace wircam::marvelmind;
using std::chrono::milliseconds;

const SocketAddress kDashboard = *SocketAddress::resolve("127.0.0.1", 49100);

class BeaconTrackerTest : public ::testing::Test {
 protected:
  static ClientConfig config() {
    ClientConfig c;
    c.beacons = {5, 6};
    c.staleAfter = milliseconds(1000);
    return c;
  }
  std::vector<PositionEvent> replyAt(milliseconds offset, uint8_t beacon, uint32_t timestamp,
                                     const SocketAddress& from = kDashboard) {
    return tracker_.onDatagram(from,
                               encode(Reply{.beacon = beacon, .timestamp = timestamp, .xMm = 1200}),
                               start_ + offset);
  }

  Clock::time_point start_ = Clock::time_point(std::chrono::hours(1));
  BeaconTracker tracker_{config(), kDashboard, 40000, start_};
};

TEST_F(BeaconTrackerTest, ANewMeasurementIsAPositionARepeatIsNot) {
  auto first = replyAt(milliseconds(100), 5, 640);
  ASSERT_EQ(first.size(), 1u);
  const auto& position = std::get<PositionReceived>(first[0]).position;
  EXPECT_EQ(position.beacon, 5);
  EXPECT_DOUBLE_EQ(position.x, 1.2);
  EXPECT_TRUE(replyAt(milliseconds(200), 5, 640).empty());  // the same measurement again
  EXPECT_EQ(tracker_.stats().repeats, 1u);
  EXPECT_EQ(replyAt(milliseconds(300), 5, 704).size(), 1u);
  EXPECT_EQ(tracker_.stats().positions, 2u);
  EXPECT_EQ(tracker_.latest(5)->received, start_ + milliseconds(300));
}

TEST_F(BeaconTrackerTest, StrangersWrongBeaconsAndJunkAreCountedAndDropped) {
  auto stranger = *SocketAddress::resolve("127.0.0.1", 49101);
  EXPECT_TRUE(replyAt(milliseconds(0), 5, 1, stranger).empty());
  EXPECT_TRUE(replyAt(milliseconds(0), 7, 1).empty());
  std::vector<uint8_t> junk(30, 0x47);
  EXPECT_TRUE(tracker_.onDatagram(kDashboard, junk, start_).empty());
  EXPECT_EQ(tracker_.stats().foreign, 1u);
  EXPECT_EQ(tracker_.stats().rejected.at("wrong beacon"), 1u);
  EXPECT_EQ(tracker_.stats().rejectedTotal(), 2u);
}

TEST_F(BeaconTrackerTest, ABeaconWithoutNewsGoesStaleOnceSayingWhyAndComesBack) {
  EXPECT_EQ(tracker_.nextDeadline(), start_ + milliseconds(1000));
  replyAt(milliseconds(500), 5, 10);
  EXPECT_EQ(tracker_.nextDeadline(), start_ + milliseconds(1000));  // beacon 6's
  auto six = tracker_.onDeadline(start_ + milliseconds(1000));
  ASSERT_EQ(six.size(), 1u);
  const auto& stale = std::get<PositionStale>(six[0]);
  EXPECT_EQ(stale.beacon, 6);
  // The dashboard answers (for beacon 5): it has nothing new of beacon 6.
  EXPECT_NE(stale.reason.find("no new position of beacon 6 for 1000 ms"), std::string::npos)
      << stale.reason;
  EXPECT_EQ(tracker_.nextDeadline(), start_ + milliseconds(1500));

  auto five = tracker_.onDeadline(start_ + milliseconds(2600));
  ASSERT_EQ(five.size(), 1u);
  EXPECT_NE(std::get<PositionStale>(five[0]).reason.find(
                "no reply from the dashboard at 127.0.0.1:49100 for 2100 ms"),
            std::string::npos)
      << std::get<PositionStale>(five[0]).reason;
  EXPECT_EQ(tracker_.nextDeadline(), std::nullopt);                       // all stale
  EXPECT_TRUE(tracker_.onDeadline(start_ + milliseconds(9000)).empty());  // stale once

  EXPECT_EQ(replyAt(milliseconds(9000), 6, 99).size(), 1u);
  EXPECT_EQ(tracker_.nextDeadline(), start_ + milliseconds(10000));
}

}  // namespace
