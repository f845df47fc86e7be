#include "marvelmind/dashboard_clock.h"

#include <gtest/gtest.h>

namespace wircam::marvelmind {
namespace {

using std::chrono::milliseconds;
using Clock = DashboardClock::Clock;

TEST(DashboardClock, UnwrapsTheCounterAndStartsOverOnARestart) {
  DashboardClock clock(TimestampUnit::kMilliseconds);
  EXPECT_DOUBLE_EQ(clock.seconds(0xFFFFFF00u), 0xFFFFFF00u / 1000.0);
  // Past 2^32 ms the counter wraps: the seconds go on.
  EXPECT_DOUBLE_EQ(clock.seconds(0x100u), (4294967296.0 + 0x100) / 1000.0);
  // A small step back is a restarted dashboard.
  EXPECT_DOUBLE_EQ(clock.seconds(0x10u), 0x10 / 1000.0);
}

TEST(DashboardClock, MapsMeasurementsByTheQuickestReply) {
  DashboardClock clock(TimestampUnit::kSixtyFourths);
  auto start = Clock::now();
  // Measured at dashboard t = 10 s (= start here); replies arrive 30, 5
  // and 50 ms after their measurement.
  auto at = [&](double dashboard, int delayMs) {
    auto received = start + milliseconds(static_cast<int>((dashboard - 10) * 1000) + delayMs);
    return clock.localTime(dashboard, received);
  };
  auto first = at(10.0, 30);
  EXPECT_EQ(first, start + milliseconds(30));  // nothing better known yet
  auto second = at(10.5, 5);
  EXPECT_LE(std::chrono::abs(second - (start + milliseconds(505))), milliseconds(1));
  // The quick reply taught the offset: a slow one is placed at its measurement.
  auto third = at(11.0, 50);
  EXPECT_LE(std::chrono::abs(third - (start + milliseconds(1005))), milliseconds(1));
}

TEST(DashboardClock, NeverPlacesAMeasurementAfterItsArrival) {
  DashboardClock clock(TimestampUnit::kMilliseconds);
  auto now = Clock::now();
  clock.localTime(5.0, now);
  // The dashboard's clock jumped ahead: clamped to the arrival.
  EXPECT_EQ(clock.localTime(9.0, now + milliseconds(100)), now + milliseconds(100));
}

}  // namespace
}  // namespace wircam::marvelmind
