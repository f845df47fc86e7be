// Keeps a recordings folder within limits by deleting finished segments
// (with their telemetry): those older than a maximum age (unless their
// telemetry shows something happened and a longer age keeps those), then the
// oldest while over a total size cap or under a free-space floor.
#pragma once

#include <chrono>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <map>
#include <optional>
#include <set>
#include <string>
#include <system_error>
#include <vector>

namespace wircam::recorder {

// Deletes a segment's video and its sidecar (what retention and the web
// server's delete do); the video's error, if it could not go.
std::error_code removeSegment(const std::filesystem::path& video);

struct RetentionLimits {
  uint64_t maxBytes = 0;           // 0 = no cap on what the recordings take
  uint64_t minFree = 0;            // 0 = no floor on the file system's free space
  std::chrono::seconds maxAge{0};  // 0 = kept whatever their age
  // Segments with events kept this long instead of maxAge (0: no exception).
  std::chrono::seconds keepEvents{0};
};

// Whether a segment's sidecar shows something happening: a tag seen, or the
// vehicle commanded off neutral (the follower, the driver, a command).
bool segmentHasEvents(const std::filesystem::path& video);

// "7d", "12h", "30m", "90s" or plain seconds; nothing for anything else.
std::optional<std::chrono::seconds> parseDuration(const std::string& text);

class Retention {
 public:
  using Logger = std::function<void(const std::string&)>;
  Retention(std::string folder, RetentionLimits limits, Logger logger);

  // Deletes segments until the limits hold at `now` (a segment's age is
  // that of its last write); never one in `open`. Returns the videos
  // deleted.
  std::vector<std::string> enforce(
      const std::set<std::string>& open,
      std::chrono::system_clock::time_point now = std::chrono::system_clock::now());
  bool active() const {
    return limits_.maxBytes > 0 || limits_.minFree > 0 || limits_.maxAge.count() > 0;
  }
  const RetentionLimits& limits() const { return limits_; }
  void setLimits(RetentionLimits limits) { limits_ = limits; }  // a reload's

 private:
  bool hasEvents(const std::filesystem::path& video);

  std::string folder_;
  RetentionLimits limits_;
  Logger logger_;
  std::map<std::string, bool> events_;  // a finished segment's never change
};

}  // namespace wircam::recorder
