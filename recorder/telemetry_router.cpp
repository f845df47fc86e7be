#include "telemetry_router.h"

namespace wircam::recorder {

namespace {
// Open sidecars: the current segment's and the one before, which late lines
// (a detection finishing after the cut) still reach.
constexpr size_t kOpenSidecars = 2;
}  // namespace

void TelemetryRouter::write(nlohmann::json line, uint64_t runningTime, int64_t unixMs) {
  MutexLock lock(mutex_);
  auto segment = planner_.segmentAt(runningTime);
  if (!segment) {
    if (early_.size() < kMaxEarlyLines) early_.push_back({std::move(line), runningTime, unixMs});
    return;
  }
  place({std::move(line), runningTime, unixMs}, *segment);
}

void TelemetryRouter::flushEarly() {
  MutexLock lock(mutex_);
  auto first = planner_.current();
  if (!first) return;
  for (auto& line : early_) place(std::move(line), *first);
  early_.clear();
}

void TelemetryRouter::place(Line line, const PlannedSegment& segment) {
  uint64_t time = std::max(line.runningTime, segment.start);
  line.json["pts"] = time - segment.start;
  line.json["utc"] = SegmentPlanner::isoUtc(line.unixMs);
  std::string text = line.json.dump();
  auto& sidecar = sidecarOf(segment.path);
  if (!sidecar.write(text) && sidecar.path() != failedPath_) {
    failedPath_ = sidecar.path();
    failure_ = "cannot write " + sidecar.path();
  }
  // A line late for a segment whose file has moved on stays in the sidecar:
  // in the text track it would land in the next file.
  track_.write(text, time, [&](GstClockTime newest) {
    auto trackSegment = planner_.segmentAt(newest);
    return trackSegment && trackSegment->start > segment.start;
  });
}

void TelemetryRouter::segmentOpened(const std::string& segment) {
  MutexLock lock(mutex_);
  auto& sidecar = sidecarOf(segment);
  if (!sidecar.create() && sidecar.path() != failedPath_) {
    failedPath_ = sidecar.path();
    failure_ = "cannot write " + sidecar.path();
  }
}

TelemetryLog& TelemetryRouter::sidecarOf(const std::string& segment) {
  std::string path = TelemetryLog::pathFor(segment);
  for (auto& sidecar : sidecars_)
    if (sidecar->path() == path) return *sidecar;
  sidecars_.push_back(std::make_unique<TelemetryLog>(segment));
  if (sidecars_.size() > kOpenSidecars) sidecars_.pop_front();
  return *sidecars_.back();
}

std::optional<std::string> TelemetryRouter::takeWriteFailure() {
  MutexLock lock(mutex_);
  return std::exchange(failure_, std::nullopt);
}

}  // namespace wircam::recorder
