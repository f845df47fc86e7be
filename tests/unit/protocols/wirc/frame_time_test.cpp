// Frame times rise by at least a millisecond, whatever order frames
// complete in, and otherwise are their arrival.
#include "wirc/frame_time.h"

#include <gtest/gtest.h>

namespace wircam::wirc {
namespace {

constexpr uint64_t kMs = 1'000'000;

TEST(FrameTime, IsTheArrivalUnlessWithinAMillisecondOfThePreviousOrBeforeIt) {
  EXPECT_EQ(nextFrameTime(5 * kMs, std::nullopt), 5 * kMs);
  EXPECT_EQ(nextFrameTime(72 * kMs, 5 * kMs), 72 * kMs);  // the usual: its own time
  // Two frames completing in the same millisecond, or one a little after:
  // a millisecond apart, so that Matroska keeps them apart.
  EXPECT_EQ(nextFrameTime(72 * kMs + 300, 72 * kMs), 73 * kMs);
  EXPECT_EQ(nextFrameTime(72 * kMs, 72 * kMs), 73 * kMs);
  // A frame completed late, after a newer one: after the newer one.
  EXPECT_EQ(nextFrameTime(60 * kMs, 72 * kMs), 73 * kMs);
  // A run of frames in one burst stays a millisecond apart, then time
  // catches up with the arrivals.
  uint64_t t = 100 * kMs;
  for (int i = 0; i < 5; ++i) t = nextFrameTime(100 * kMs, t);
  EXPECT_EQ(t, 105 * kMs);
  EXPECT_EQ(nextFrameTime(167 * kMs, t), 167 * kMs);
}

}  // namespace
}  // namespace wircam::wirc
