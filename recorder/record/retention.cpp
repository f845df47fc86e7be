#include "record/retention.h"

#include <glib.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
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

std::optional<std::chrono::seconds> parseDuration(const std::string& text) {
  if (text.empty()) return std::nullopt;
  char* end = nullptr;
  double value = g_ascii_strtod(text.c_str(), &end);
  std::string unit(end);
  static const std::map<std::string, double> kUnits = {{"", 1},     {"s", 1},     {"m", 60},
                                                       {"h", 3600}, {"d", 86400}, {"w", 7 * 86400}};
  auto scale = kUnits.find(unit);
  if (end == text.c_str() || scale == kUnits.end() || !std::isfinite(value) || value < 0 ||
      value * scale->second > 100.0 * 365 * 86400)
    return std::nullopt;
  return std::chrono::seconds(static_cast<int64_t>(std::llround(value * scale->second)));
}

bool segmentHasEvents(const fs::path& video) {
  std::ifstream sidecar(TelemetryLog::pathFor(video.string()));
  for (std::string text; std::getline(sidecar, text);) {
    auto line = nlohmann::json::parse(text, nullptr, false);
    if (!line.is_object()) continue;
    std::string type = line.value("type", "");
    if (type == "detections" && line.contains("detections") && line["detections"].is_array() &&
        !line["detections"].empty())
      return true;
    if (type == "control" &&
        (line.value("steering-pulse", 1500) != 1500 || line.value("throttle-pulse", 1500) != 1500))
      return true;
    if (type == "drive" || type == "command") return true;
  }
  return false;
}

bool Retention::hasEvents(const fs::path& video) {
  auto known = events_.find(video.string());
  if (known != events_.end()) return known->second;
  return events_[video.string()] = segmentHasEvents(video);
}

std::vector<std::string> Retention::enforce(const std::set<std::string>& open,
                                            std::chrono::system_clock::time_point now) {
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
  auto remove = [&](const Segment& segment, const std::string& why) {
    removeSegment(segment.video);
    events_.erase(segment.video.string());
    total -= segment.bytes;
    deleted.push_back(segment.video.string());
    logger_("deleted " + segment.video.filename().string() + " (" + why + ")");
  };
  if (limits_.maxAge.count() > 0) {
    std::erase_if(segments, [&](const Segment& segment) {
      auto age = now - std::chrono::file_clock::to_sys(segment.written);
      if (age <= limits_.maxAge) return false;
      bool kept = age <= limits_.keepEvents && hasEvents(segment.video);
      if (!kept) remove(segment, "older than --max-age");
      return !kept;
    });
  }
  for (const auto& segment : segments) {
    bool overSize = limits_.maxBytes > 0 && total > limits_.maxBytes;
    bool underFree = limits_.minFree > 0 && freeBytes(folder_) < limits_.minFree;
    if (!overSize && !underFree) break;
    remove(segment, overSize ? "over --max-bytes" : "under --min-free");
  }
  return deleted;
}

}  // namespace wircam::recorder
