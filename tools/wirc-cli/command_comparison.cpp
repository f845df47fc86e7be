#include "command_comparison.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>

namespace wircam::cli {

namespace {

int64_t frameKey(int64_t ptsNs) { return static_cast<int64_t>(std::llround(ptsNs / 1e6)); }

// -1 right, 0 straight, +1 left (a steering pulse above neutral turns left).
int direction(int steering) {
  if (steering > 1500 + kStraight) return 1;
  if (steering < 1500 - kStraight) return -1;
  return 0;
}

// Each line of `in` as a JSON object; a line that is not one is an error
// naming it.
template <typename Take>
std::optional<std::string> eachLine(std::istream& in, Take take) {
  std::string text;
  for (size_t number = 1; std::getline(in, text); ++number) {
    if (text.empty()) continue;
    auto line = nlohmann::json::parse(text, nullptr, false);
    if (!line.is_object()) return "line " + std::to_string(number) + " is not a JSON object";
    if (auto problem = take(line)) return "line " + std::to_string(number) + ": " + *problem;
  }
  return std::nullopt;
}

}  // namespace

Expected<CommandsByFrame, std::string> recordedCommands(std::istream& sidecar,
                                                        const std::string& segment) {
  CommandsByFrame commands;
  auto problem = eachLine(sidecar, [&](const nlohmann::json& line) -> std::optional<std::string> {
    if (line.value("type", "") != "control") return std::nullopt;
    if (!line.contains("pts") || !line["pts"].is_number() || !line.contains("steering-pulse") ||
        !line["steering-pulse"].is_number() || !line.contains("throttle-pulse") ||
        !line["throttle-pulse"].is_number())
      return "a control line without pts, steering-pulse and throttle-pulse";
    commands[{segment, frameKey(line["pts"].get<int64_t>())}] = {line["steering-pulse"].get<int>(),
                                                                 line["throttle-pulse"].get<int>()};
    return std::nullopt;
  });
  if (problem) return unexpected(*problem);
  if (commands.empty())
    return unexpected(std::string("no control lines: record with wirc-recorder --follow"));
  return commands;
}

Expected<CommandsByFrame, std::string> replayedCommands(std::istream& lines, int steeringChannel,
                                                        int throttleChannel) {
  CommandsByFrame commands;
  auto problem = eachLine(lines, [&](const nlohmann::json& line) -> std::optional<std::string> {
    if (!line.contains("pts") || !line["pts"].is_number() || !line.contains("channels") ||
        !line["channels"].is_array())
      return "no pts and channels (not a wirc-sim --commands-out file?)";
    const auto& channels = line["channels"];
    auto channel = [&](int number) {
      return number >= 1 && static_cast<size_t>(number) <= channels.size() &&
                     channels[number - 1].is_number()
                 ? channels[number - 1].get<int>()
                 : 1500;
    };
    // Replays written before segments were named match by time alone.
    std::string segment =
        line.contains("segment") && line["segment"].is_string()
            ? std::filesystem::path(line["segment"].get<std::string>()).stem().string()
            : "";
    commands[{segment, frameKey(line["pts"].get<int64_t>())}] = {channel(steeringChannel),
                                                                 channel(throttleChannel)};
    return std::nullopt;
  });
  if (problem) return unexpected(*problem);
  if (commands.empty()) return unexpected(std::string("no commands"));
  return commands;
}

Expected<CommandsByFrame, std::string> recordedCommandsIn(const std::vector<std::string>& paths) {
  namespace fs = std::filesystem;
  CommandsByFrame commands;
  auto take = [&](const fs::path& sidecar) -> std::optional<std::string> {
    std::ifstream in(sidecar);
    if (!in) return "cannot read " + sidecar.string();
    auto some = recordedCommands(in, sidecar.stem().string());
    if (!some) return sidecar.string() + ": " + some.error();
    commands.merge(*some);
    return std::nullopt;
  };
  for (const auto& path : paths) {
    std::error_code error;
    if (!fs::is_directory(path, error)) {
      if (auto problem = take(path)) return unexpected(*problem);
      continue;
    }
    // A folder's sidecars: those beside a segment; one without control lines
    // (a camera that did not follow) is left out.
    std::vector<fs::path> sidecars;
    for (const auto& entry : fs::directory_iterator(path, error))
      if (entry.path().extension() == ".jsonl" &&
          (fs::exists(fs::path(entry.path()).replace_extension(".mkv"), error) ||
           fs::exists(fs::path(entry.path()).replace_extension(".mp4"), error)))
        sidecars.push_back(entry.path());
    std::sort(sidecars.begin(), sidecars.end());
    size_t before = commands.size();
    for (const auto& sidecar : sidecars) {
      std::ifstream in(sidecar);
      if (auto some = recordedCommands(in, sidecar.stem().string())) commands.merge(*some);
    }
    if (commands.size() == before)
      return unexpected(path +
                        ": no sidecar with control lines: record with wirc-recorder --follow");
  }
  return commands;
}

Comparison compareCommands(const CommandsByFrame& recorded, const CommandsByFrame& replayed) {
  Comparison c;
  uint64_t run = 0;
  for (const auto& [frame, mine] : recorded) {
    auto other = replayed.find(frame);
    if (other == replayed.end()) other = replayed.find({"", frame.ms});
    if (other == replayed.end()) continue;
    const FrameCommand& theirs = other->second;
    ++c.frames;
    double steering = std::abs(mine.steering - theirs.steering);
    double throttle = std::abs(mine.throttle - theirs.throttle);
    c.meanSteeringDelta += steering;
    c.meanThrottleDelta += throttle;
    c.maxSteeringDelta = std::max(c.maxSteeringDelta, steering);
    c.maxThrottleDelta = std::max(c.maxThrottleDelta, throttle);
    c.recordedSteering += std::abs(mine.steering - 1500);
    c.replayedSteering += std::abs(theirs.steering - 1500);
    bool opposite = direction(mine.steering) * direction(theirs.steering) < 0;
    c.directionDisagreements += opposite;
    run = opposite ? run + 1 : 0;
    c.longestDisagreement = std::max(c.longestDisagreement, run);
  }
  if (c.frames) {
    auto n = static_cast<double>(c.frames);
    c.meanSteeringDelta /= n;
    c.meanThrottleDelta /= n;
    c.recordedSteering /= n;
    c.replayedSteering /= n;
  }
  return c;
}

nlohmann::json comparisonJson(const Comparison& c) {
  return {{"frames", c.frames},
          {"steering_delta_us", {{"mean", c.meanSteeringDelta}, {"max", c.maxSteeringDelta}}},
          {"throttle_delta_us", {{"mean", c.meanThrottleDelta}, {"max", c.maxThrottleDelta}}},
          {"steering_from_neutral_us",
           {{"recorded", c.recordedSteering}, {"replayed", c.replayedSteering}}},
          {"direction_disagreements", c.directionDisagreements},
          {"longest_disagreement_frames", c.longestDisagreement}};
}

std::string comparisonText(const Comparison& c) {
  char text[640];
  double share = c.frames ? 100.0 * static_cast<double>(c.directionDisagreements) /
                                static_cast<double>(c.frames)
                          : 0;
  std::snprintf(text, sizeof text,
                "frames compared          %llu\n"
                "steering |Δ|             mean %.1f µs, max %.0f µs\n"
                "throttle |Δ|             mean %.1f µs, max %.0f µs\n"
                "steering from neutral    recorded mean %.1f µs, replayed mean %.1f µs\n"
                "steering direction       differs on %llu frames (%.1f %%)\n"
                "longest disagreement     %llu frames\n",
                static_cast<unsigned long long>(c.frames), c.meanSteeringDelta, c.maxSteeringDelta,
                c.meanThrottleDelta, c.maxThrottleDelta, c.recordedSteering, c.replayedSteering,
                static_cast<unsigned long long>(c.directionDisagreements), share,
                static_cast<unsigned long long>(c.longestDisagreement));
  return text;
}

}  // namespace wircam::cli
