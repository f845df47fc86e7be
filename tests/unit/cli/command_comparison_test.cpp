// wirc-cli compare-commands: reading both files and the arithmetic.
#include "command_comparison.h"

#include <gtest/gtest.h>

#include <sstream>

namespace wircam::cli {
namespace {

// A sidecar's control line for the frame at `ptsNs`.
std::string control(int64_t ptsNs, int steering, int throttle) {
  return nlohmann::json{{"type", "control"},
                        {"pts", ptsNs},
                        {"steering-pulse", steering},
                        {"throttle-pulse", throttle}}
             .dump() +
         "\n";
}

// A --commands-out line: a PCD during the frame at `ptsNs` (ms precision)
// of `segment`.
std::string pcd(int64_t ptsNs, int steering, int throttle, const std::string& segment = "") {
  std::vector<int> channels(12, 1500);
  channels[0] = steering;
  channels[1] = throttle;
  nlohmann::json line = {{"frame", 0}, {"pts", ptsNs}, {"channels", channels}};
  if (!segment.empty()) line["segment"] = segment;
  return line.dump() + "\n";
}

TEST(CommandComparison, MatchesFramesAtTheMillisecondMatroskaKeepsAndComparesThem) {
  std::istringstream sidecar(R"({"type":"detections","pts":0})"
                             "\n" +
                             control(0, 1600, 1700) + control(66676912, 1400, 1700) +
                             control(133353824, 1505, 1500));
  // The replay's frames in whole ms; the second frame had a keepalive and
  // then the command: the last one counts. A frame the recording lacks is
  // left out.
  std::istringstream replay(pcd(0, 1580, 1690) + pcd(67000000, 1500, 1500) +
                            pcd(67000000, 1640, 1700) + pcd(133000000, 1490, 1500) +
                            pcd(200000000, 1500, 1500));
  auto recorded = recordedCommands(sidecar);
  auto replayed = replayedCommands(replay);
  ASSERT_TRUE(recorded.has_value()) << recorded.error();
  ASSERT_TRUE(replayed.has_value()) << replayed.error();
  auto c = compareCommands(*recorded, *replayed);
  EXPECT_EQ(c.frames, 3u);
  EXPECT_DOUBLE_EQ(c.meanSteeringDelta, (20 + 240 + 15) / 3.0);
  EXPECT_DOUBLE_EQ(c.maxSteeringDelta, 240);
  EXPECT_DOUBLE_EQ(c.meanThrottleDelta, (10 + 0 + 0) / 3.0);
  EXPECT_DOUBLE_EQ(c.recordedSteering, (100 + 100 + 5) / 3.0);
  EXPECT_DOUBLE_EQ(c.replayedSteering, (80 + 140 + 10) / 3.0);
  // Frame 2 steers right recorded and left replayed; frame 3 is straight
  // ahead both ways (within 10 µs).
  EXPECT_EQ(c.directionDisagreements, 1u);
  EXPECT_EQ(c.longestDisagreement, 1u);
  auto json = comparisonJson(c);
  EXPECT_EQ(json["frames"], 3);
  EXPECT_EQ(json["direction_disagreements"], 1);
  EXPECT_NE(comparisonText(c).find("differs on 1 frames (33.3 %)"), std::string::npos)
      << comparisonText(c);
}

TEST(CommandComparison, TheLongestRunOfDisagreementIsConsecutiveFrames) {
  std::string recorded, replayed;
  const bool opposite[] = {true, true, false, true, true, true, false};
  for (int i = 0; i < 7; ++i) {
    recorded += control(i * 100000000LL, 1600, 1500);
    replayed += pcd(i * 100000000LL, opposite[i] ? 1400 : 1600, 1500);
  }
  std::istringstream a(recorded), b(replayed);
  auto c = compareCommands(*recordedCommands(a), *replayedCommands(b));
  EXPECT_EQ(c.directionDisagreements, 5u);
  EXPECT_EQ(c.longestDisagreement, 3u);
}

TEST(CommandComparison, FramesOfDifferentSegmentsAtTheSamePtsAreNotMixed) {
  // Every segment starts at pts 0: two segments steering opposite ways at
  // the same times, replayed exactly.
  std::istringstream first(control(0, 1600, 1500) + control(66000000, 1610, 1500));
  std::istringstream second(control(0, 1400, 1500) + control(66000000, 1390, 1500));
  auto recorded = recordedCommands(first, "rover-cam0-20261124T145935Z");
  auto more = recordedCommands(second, "rover-cam0-20261124T145937Z");
  ASSERT_TRUE(recorded && more);
  recorded->merge(*more);
  std::istringstream replay(pcd(0, 1400, 1500, "rover-cam0-20261124T145937Z.mkv") +
                            pcd(0, 1600, 1500, "rover-cam0-20261124T145935Z.mkv") +
                            pcd(66000000, 1390, 1500, "rover-cam0-20261124T145937Z.mkv") +
                            pcd(66000000, 1610, 1500, "rover-cam0-20261124T145935Z.mkv"));
  auto replayed = replayedCommands(replay);
  ASSERT_TRUE(replayed.has_value()) << replayed.error();
  auto c = compareCommands(*recorded, *replayed);
  EXPECT_EQ(c.frames, 4u);
  EXPECT_DOUBLE_EQ(c.meanSteeringDelta, 0);
  EXPECT_EQ(c.directionDisagreements, 0u);
}

TEST(CommandComparison, SaysWhatIsWrongWithAFile) {
  std::istringstream noControl(R"({"type":"detections","pts":0})"
                               "\n");
  auto none = recordedCommands(noControl);
  ASSERT_FALSE(none.has_value());
  EXPECT_NE(none.error().find("no control lines"), std::string::npos);
  std::istringstream garbage(
      "{\"type\":\"control\",\"pts\":0,\"steering-pulse\":1500,"
      "\"throttle-pulse\":1500}\nnot json\n");
  auto broken = recordedCommands(garbage);
  ASSERT_FALSE(broken.has_value());
  EXPECT_EQ(broken.error(), "line 2 is not a JSON object");
  std::istringstream sidecarAsReplay(control(0, 1500, 1500));
  auto swapped = replayedCommands(sidecarAsReplay);
  ASSERT_FALSE(swapped.has_value());
  EXPECT_NE(swapped.error().find("not a wirc-sim --commands-out file"), std::string::npos);
}

}  // namespace
}  // namespace wircam::cli
