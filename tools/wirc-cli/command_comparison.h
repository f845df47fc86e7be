// wirc-cli compare-commands: what a controller commanded on a recorded drive
// against what it commands when the drive is replayed (wirc-sim --replay
// --commands-out), frame by frame.
#pragma once

#include <cstdint>
#include <istream>
#include <map>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "common/expected.h"

namespace wircam::cli {

// One frame's command: steering and throttle pulses, µs.
struct FrameCommand {
  int steering = 1500, throttle = 1500;
};

// A frame: its segment (the file's name without its extension: every
// segment starts at pts 0) and its time in it, in whole milliseconds (what
// Matroska keeps of a frame's time: the sidecar's pts is finer).
struct FrameKey {
  std::string segment;
  int64_t ms = 0;
  auto operator<=>(const FrameKey&) const = default;
};
using CommandsByFrame = std::map<FrameKey, FrameCommand>;

// A recorder's sidecar, of the segment named `segment`: its "control" lines
// (steering-pulse, throttle-pulse), each at the pts of the frame it was made
// from.
Expected<CommandsByFrame, std::string> recordedCommands(std::istream& sidecar,
                                                        const std::string& segment = "");
// The control lines of every sidecar in `paths`: sidecar files, or folders
// of recordings (each .jsonl beside a segment of the same name).
Expected<CommandsByFrame, std::string> recordedCommandsIn(const std::vector<std::string>& paths);
// A --commands-out file: each PCD with the segment and pts of the frame on
// screen; the last one that came during a frame is its command. Steering
// and throttle are PCD channels `steeringChannel` and `throttleChannel`
// (1-based).
Expected<CommandsByFrame, std::string> replayedCommands(std::istream& lines,
                                                        int steeringChannel = 1,
                                                        int throttleChannel = 2);

struct Comparison {
  uint64_t frames = 0;                                 // in both
  double meanSteeringDelta = 0, maxSteeringDelta = 0;  // |recorded − replayed|, µs
  double meanThrottleDelta = 0, maxThrottleDelta = 0;
  // Mean |steering − 1500| of each, µs: how hard each one steers.
  double recordedSteering = 0, replayedSteering = 0;
  // Frames where one steers left and the other right (a pulse within
  // kStraight of neutral is straight ahead, and disagrees with neither).
  uint64_t directionDisagreements = 0;
  uint64_t longestDisagreement = 0;  // consecutive compared frames
};
constexpr int kStraight = 10;

Comparison compareCommands(const CommandsByFrame& recorded, const CommandsByFrame& replayed);

// The comparison as text lines, or as one JSON object.
std::string comparisonText(const Comparison& comparison);
nlohmann::json comparisonJson(const Comparison& comparison);

}  // namespace wircam::cli
