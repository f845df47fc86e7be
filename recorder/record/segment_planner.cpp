#include "record/segment_planner.h"

#include <ctime>

namespace wircam::recorder {

namespace {

std::tm utcOf(int64_t unixMs) {
  std::time_t seconds = static_cast<std::time_t>(unixMs / 1000);
  std::tm tm{};
  gmtime_r(&seconds, &tm);
  return tm;
}

}  // namespace

double PlannedSegment::durationSeconds() const {
  double span = static_cast<double>(lastFrame - start) / 1e9;
  double period = frames > 1 ? span / static_cast<double>(frames - 1) : 0;
  return span + period;
}

SegmentPlanner::SegmentPlanner(std::filesystem::path folder, std::string stem,
                               std::string extension, SegmentLimits limits)
    : folder_(std::move(folder)),
      stem_(std::move(stem)),
      extension_(std::move(extension)),
      limits_(limits) {}

std::string SegmentPlanner::compactUtc(int64_t unixMs) {
  std::tm tm = utcOf(unixMs);
  char text[32];
  std::strftime(text, sizeof text, "%Y%m%dT%H%M%SZ", &tm);
  return text;
}

std::string SegmentPlanner::isoUtc(int64_t unixMs) {
  std::tm tm = utcOf(unixMs);
  char text[40];
  size_t n = std::strftime(text, sizeof text, "%Y-%m-%dT%H:%M:%S", &tm);
  std::snprintf(text + n, sizeof text - n, ".%03dZ", static_cast<int>(unixMs % 1000));
  return text;
}

std::string SegmentPlanner::nameFor(int64_t unixMs) {
  std::string base = stem_ + "-" + compactUtc(unixMs);
  for (int counter = 1;; ++counter) {
    // "_2" sorts after the name without it ('_' after '.'), so the files of
    // one camera list in the order they were recorded ("-2" came first).
    std::string name = base + (counter == 1 ? "" : "_" + std::to_string(counter)) + extension_;
    std::error_code error;
    if (!used_.count(name) && !std::filesystem::exists(folder_ / name, error)) {
      used_.insert(name);
      return (folder_ / name).string();
    }
  }
}

SegmentPlanner::Cut SegmentPlanner::onFrame(uint64_t pts,
                                            const std::function<int64_t()>& unixMsNow) {
  MutexLock lock(mutex_);
  Cut cut = Cut::kNone;
  if (segments_.empty()) {
    cut = Cut::kFirst;
  } else {
    const PlannedSegment& open = segments_.back();
    bool full = limits_.maxDuration > 0 && !finishing_ && pts >= open.start + limits_.maxDuration;
    bool gap = pts > open.lastFrame + limits_.maxGap;
    if (full || gap || splitPending_) cut = Cut::kNext;
  }
  if (cut != Cut::kNone) {
    splitPending_ = false;
    int64_t unixMs = unixMsNow();
    segments_.push_back(
        {.path = nameFor(unixMs), .startUnixMs = unixMs, .start = pts, .lastFrame = pts});
    if (segments_.size() > kKept) segments_.erase(segments_.begin());
  }
  PlannedSegment& open = segments_.back();
  open.lastFrame = std::max(open.lastFrame, pts);
  ++open.frames;
  return cut;
}

void SegmentPlanner::addBytes(uint64_t bytes) {
  MutexLock lock(mutex_);
  if (segments_.empty()) return;
  PlannedSegment& open = segments_.back();
  open.bytes += bytes;
  if (limits_.maxBytes > 0 && open.bytes >= limits_.maxBytes) splitPending_ = true;
}

void SegmentPlanner::finishing() {
  MutexLock lock(mutex_);
  finishing_ = true;
}

std::optional<PlannedSegment> SegmentPlanner::segmentAt(uint64_t runningTime) const {
  MutexLock lock(mutex_);
  if (segments_.empty()) return std::nullopt;
  for (auto it = segments_.rbegin(); it != segments_.rend(); ++it)
    if (it->start <= runningTime) return *it;
  return segments_.front();
}

std::optional<PlannedSegment> SegmentPlanner::segmentReaching(uint64_t runningTime) const {
  MutexLock lock(mutex_);
  for (const auto& segment : segments_)
    if (runningTime <= segment.lastFrame) return segment;
  return std::nullopt;
}

std::optional<PlannedSegment> SegmentPlanner::segmentOf(const std::string& path) const {
  MutexLock lock(mutex_);
  for (const auto& segment : segments_)
    if (segment.path == path) return segment;
  return std::nullopt;
}

std::optional<PlannedSegment> SegmentPlanner::current() const {
  MutexLock lock(mutex_);
  if (segments_.empty()) return std::nullopt;
  return segments_.back();
}

}  // namespace wircam::recorder
