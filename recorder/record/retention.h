// Keeps a recordings folder within limits by deleting the oldest finished
// segments (with their telemetry): a total size cap and a free-space floor.
#pragma once

#include <cstdint>
#include <filesystem>
#include <functional>
#include <set>
#include <string>
#include <system_error>
#include <vector>

namespace wircam::recorder {

// Deletes a segment's video and its sidecar (what retention and the web
// server's delete do); the video's error, if it could not go.
std::error_code removeSegment(const std::filesystem::path& video);

struct RetentionLimits {
  uint64_t maxBytes = 0;  // 0 = no cap on what the recordings take
  uint64_t minFree = 0;   // 0 = no floor on the file system's free space
};

class Retention {
 public:
  using Logger = std::function<void(const std::string&)>;
  Retention(std::string folder, RetentionLimits limits, Logger logger);

  // Deletes oldest segments until the limits hold; never one in `open`.
  // Returns the videos deleted.
  std::vector<std::string> enforce(const std::set<std::string>& open);
  bool active() const { return limits_.maxBytes > 0 || limits_.minFree > 0; }

 private:
  std::string folder_;
  RetentionLimits limits_;
  Logger logger_;
};

}  // namespace wircam::recorder
