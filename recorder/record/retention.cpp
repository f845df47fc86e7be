#include "record/retention.h"

#include <algorithm>
#include <filesystem>
#include <vector>

#include "record/disk_guard.h"
#include "record/telemetry_log.h"

namespace wircam::recorder {

namespace fs = std::filesystem;

Retention::Retention(std::string folder, RetentionLimits limits, Logger logger)
    : folder_(std::move(folder)), limits_(limits), logger_(std::move(logger)) {}

namespace {

struct Segment {
  fs::path video;
  fs::file_time_type written;
  uint64_t bytes;  // video and telemetry
};

}  // namespace

std::error_code removeSegment(const fs::path& video) {
  std::error_code error, sidecarError;
  fs::remove(video, error);
  // A segment may have no sidecar (a crash before its first line).
  fs::remove(TelemetryLog::pathFor(video.string()), sidecarError);
  return error;
}

std::vector<std::string> Retention::enforce(const std::set<std::string>& open) {
  std::vector<std::string> deleted;
  if (!active()) return deleted;
  std::vector<Segment> segments;
  uint64_t total = 0;
  std::error_code error;
  for (const auto& entry : fs::directory_iterator(folder_, error)) {
    auto extension = entry.path().extension();
    if (extension != ".mkv" && extension != ".mp4") continue;
    fs::path sidecar = TelemetryLog::pathFor(entry.path().string());
    uint64_t bytes =
        entry.file_size(error) + (fs::exists(sidecar) ? fs::file_size(sidecar, error) : 0);
    total += bytes;
    if (!open.count(entry.path().string()))
      segments.push_back({entry.path(), entry.last_write_time(error), bytes});
  }
  std::sort(segments.begin(), segments.end(),
            [](const Segment& a, const Segment& b) { return a.written < b.written; });
  for (const auto& segment : segments) {
    bool overSize = limits_.maxBytes > 0 && total > limits_.maxBytes;
    bool underFree = limits_.minFree > 0 && freeBytes(folder_) < limits_.minFree;
    if (!overSize && !underFree) break;
    removeSegment(segment.video);
    total -= segment.bytes;
    deleted.push_back(segment.video.string());
    logger_("deleted " + segment.video.filename().string() +
            (overSize ? " (over --max-bytes)" : " (under --min-free)"));
  }
  return deleted;
}

}  // namespace wircam::recorder
