// Where segments begin: at the first frame, at their length (not once the
// recording stops), at the byte limit and at a gap in the frames; and which
// segment a time belongs to.
#include "record/segment_planner.h"

#include <gtest/gtest.h>

#include <fstream>

#include "temp_folder_test.h"

namespace {

namespace fs = std::filesystem;
using wircam::recorder::SegmentLimits;
using wircam::recorder::SegmentPlanner;
using Cut = SegmentPlanner::Cut;

constexpr uint64_t kSecond = 1'000'000'000;
constexpr uint64_t kFrame = kSecond / 15;
constexpr int64_t kNoon = 1795348800000;  // 2026-11-22T12:00:00Z

// A wall clock that says `unixMs`.
std::function<int64_t()> at(int64_t unixMs) {
  return [unixMs] { return unixMs; };
}

class SegmentPlannerTest : public wircam::testing::TempFolderTest {
 protected:
  SegmentPlanner planner(SegmentLimits limits) {
    return SegmentPlanner(folder_, "rover-cam0", ".mkv", limits);
  }
  // Frames at 15 fps from `from` for `count` frames; the cuts they made.
  static std::vector<uint64_t> feed(SegmentPlanner& p, uint64_t from, int count) {
    std::vector<uint64_t> cuts;
    for (int i = 0; i < count; ++i) {
      uint64_t pts = from + static_cast<uint64_t>(i) * kFrame;
      if (p.onFrame(pts, at(kNoon + static_cast<int64_t>(pts / 1'000'000))) != Cut::kNone)
        cuts.push_back(pts);
    }
    return cuts;
  }
};

TEST_F(SegmentPlannerTest, TheFirstFrameOpensTheFirstSegmentNamedByItsUtcTime) {
  auto p = planner({.maxDuration = 10 * kSecond});
  EXPECT_FALSE(p.current());
  EXPECT_EQ(p.onFrame(5 * kSecond, at(kNoon)), Cut::kFirst);
  EXPECT_EQ(p.onFrame(5 * kSecond + kFrame, at(kNoon + 66)), Cut::kNone);
  auto open = p.current();
  ASSERT_TRUE(open);
  EXPECT_EQ(open->path, (folder_ / "rover-cam0-20261122T120000Z.mkv").string());
  EXPECT_EQ(open->start, 5 * kSecond);
  EXPECT_EQ(open->frames, 2u);
}

TEST_F(SegmentPlannerTest, CutsAtTheSegmentLengthOnTheFrameThatReachesIt) {
  auto p = planner({.maxDuration = 2 * kSecond});
  auto cuts = feed(p, 0, 15 * 5);  // 5 s
  ASSERT_EQ(cuts.size(), 3u);      // 0, 2 and 4 s
  EXPECT_EQ(cuts[0], 0u);
  EXPECT_GE(cuts[1], 2 * kSecond);
  EXPECT_LT(cuts[1], 2 * kSecond + kFrame);
  EXPECT_NEAR(static_cast<double>(cuts[2] - cuts[1]), 2e9, static_cast<double>(kFrame));
}

TEST_F(SegmentPlannerTest, AGapInTheFramesEndsTheSegmentAndTheNextFrameOpensAnother) {
  auto p = planner({.maxDuration = 60 * kSecond});
  feed(p, 0, 30);
  uint64_t back = 30 * kFrame + 5 * kSecond;  // the device was gone for 5 s
  EXPECT_EQ(p.onFrame(back, at(kNoon + 7000)), Cut::kNext);
  EXPECT_EQ(p.current()->start, back);
  // A hiccup shorter than the limit does not cut.
  EXPECT_EQ(p.onFrame(back + 400'000'000, at(kNoon + 7400)), Cut::kNone);
}

TEST_F(SegmentPlannerTest, TheByteLimitCutsAtTheNextFrame) {
  auto p = planner({.maxBytes = 1000});
  p.onFrame(0, at(kNoon));
  p.addBytes(600);
  EXPECT_EQ(p.onFrame(kFrame, at(kNoon)), Cut::kNone);
  p.addBytes(600);
  EXPECT_EQ(p.onFrame(2 * kFrame, at(kNoon)), Cut::kNext);
  EXPECT_EQ(p.current()->bytes, 0u);
}

TEST_F(SegmentPlannerTest, WhileTheRecordingStopsTheLengthNoLongerCutsButTheByteLimitDoes) {
  auto p = planner({.maxDuration = 2 * kSecond, .maxBytes = 1000});
  feed(p, 0, 29);  // up to just before 2 s
  p.finishing();
  // The frames the stop still lets through stay in the open file.
  EXPECT_TRUE(feed(p, 29 * kFrame, 5).empty());
  EXPECT_EQ(p.current()->start, 0u);
  EXPECT_EQ(p.current()->frames, 34u);
  p.addBytes(1200);
  EXPECT_EQ(p.onFrame(34 * kFrame, at(kNoon)), Cut::kNext);
}

TEST_F(SegmentPlannerTest, NamesThatWouldCollideGetACounterAndStillSortInTimeOrder) {
  std::ofstream(folder_ / "rover-cam0-20261122T120000Z.mkv") << "from an earlier run";
  auto p = planner({.maxDuration = kSecond / 2});
  p.onFrame(0, at(kNoon));
  EXPECT_EQ(fs::path(p.current()->path).filename(), "rover-cam0-20261122T120000Z_2.mkv");
  std::string second = p.current()->path;
  p.onFrame(kSecond / 2, at(kNoon + 500));  // the same second
  EXPECT_EQ(fs::path(p.current()->path).filename(), "rover-cam0-20261122T120000Z_3.mkv");
  // As `ls` lists them: the earlier run's, then these two, in time order.
  EXPECT_LT((folder_ / "rover-cam0-20261122T120000Z.mkv").string(), second);
  EXPECT_LT(second, p.current()->path);
}

TEST_F(SegmentPlannerTest, ATimeBelongsToTheLastSegmentStartedAtOrBeforeIt) {
  auto p = planner({.maxDuration = 2 * kSecond});
  EXPECT_FALSE(p.segmentAt(0));
  feed(p, kSecond, 15 * 5);                   // segments at 1, 3 and 5 s
  EXPECT_EQ(p.segmentAt(0)->start, kSecond);  // before the first frame: the first
  EXPECT_EQ(p.segmentAt(2 * kSecond)->start, kSecond);
  auto second = p.segmentAt(3 * kSecond + kFrame);
  EXPECT_GE(second->start, 3 * kSecond);
  EXPECT_LT(second->start, 3 * kSecond + kFrame);
  EXPECT_EQ(p.segmentOf(second->path)->start, second->start);
}

TEST_F(SegmentPlannerTest, ALineReachesNoSegmentUntilAFrameCoversIt) {
  auto p = planner({});
  EXPECT_FALSE(p.segmentReaching(0)) << "no frame yet";
  feed(p, kSecond, 15);  // 1 s .. 1.93 s
  uint64_t last = kSecond + 14 * kFrame;
  EXPECT_EQ(p.segmentReaching(0)->start, kSecond) << "before the first frame: its start";
  EXPECT_EQ(p.segmentReaching(last)->start, kSecond);
  EXPECT_FALSE(p.segmentReaching(last + 1)) << "past the newest frame: it waits";
  // An outage: the device is back at 5 s, in a segment of its own.
  feed(p, 5 * kSecond, 3);
  EXPECT_EQ(p.segmentReaching(last)->start, kSecond);
  EXPECT_EQ(p.segmentReaching(last + 1)->start, 5 * kSecond) << "the outage: the next start";
  EXPECT_EQ(p.segmentReaching(4 * kSecond)->start, 5 * kSecond);
  EXPECT_FALSE(p.segmentReaching(5 * kSecond + 2 * kFrame + 1));
}

TEST_F(SegmentPlannerTest, ASegmentLastsItsFramesSpanAndOnePeriod) {
  auto p = planner({});
  feed(p, 0, 16);
  EXPECT_NEAR(p.current()->durationSeconds(), 16.0 / 15, 1e-6);
}

TEST(SegmentPlannerUtc, FormatsForNamesAndForTelemetry) {
  EXPECT_EQ(SegmentPlanner::compactUtc(kNoon + 5123), "20261122T120005Z");
  EXPECT_EQ(SegmentPlanner::isoUtc(kNoon + 5123), "2026-11-22T12:00:05.123Z");
}

}  // namespace
