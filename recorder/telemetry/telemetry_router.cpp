#include "telemetry/telemetry_router.h"

#include <algorithm>

namespace wircam::recorder {

namespace {
// Open sidecars: the current segment's and the one before, which late lines
// (a detection finishing after the cut) still reach.
constexpr size_t kOpenSidecars = 2;
}  // namespace

void TelemetryRouter::write(nlohmann::json line, uint64_t runningTime, int64_t unixMs) {
  MutexLock lock(mutex_);
  if (finished_) return placeByItsLastFrame({std::move(line), runningTime, unixMs});
  if (waiting_.empty()) {
    if (auto segment = planner_.segmentReaching(runningTime)) {
      place({std::move(line), runningTime, unixMs}, *segment,
            std::max(runningTime, segment->start));
      return;
    }
  }
  // Behind a waiting line (so lines keep their order), or past the video.
  if (waiting_.size() == kMaxWaiting) {
    waiting_.pop_front();
    ++dropped_;
  }
  waiting_.push_back({std::move(line), runningTime, unixMs});
}

void TelemetryRouter::onFrame() {
  MutexLock lock(mutex_);
  writeWaiting();
}

void TelemetryRouter::writeWaiting() {
  while (!waiting_.empty()) {
    Line& line = waiting_.front();
    auto segment = planner_.segmentReaching(line.runningTime);
    if (!segment) return;
    uint64_t time = std::max(line.runningTime, segment->start);
    place(std::move(line), *segment, time);
    waiting_.pop_front();
  }
}

void TelemetryRouter::finish() {
  MutexLock lock(mutex_);
  writeWaiting();
  finished_ = true;
  for (auto& line : waiting_) placeByItsLastFrame(std::move(line));
  waiting_.clear();
}

std::deque<TelemetryRouter::Line> TelemetryRouter::handOver() {
  MutexLock lock(mutex_);
  writeWaiting();
  return std::exchange(waiting_, {});
}

void TelemetryRouter::placeByItsLastFrame(Line line) {
  auto segment = planner_.segmentAt(line.runningTime);
  if (!segment) return;
  uint64_t time = std::clamp(line.runningTime, segment->start, segment->lastFrame);
  place(std::move(line), *segment, time);
}

void TelemetryRouter::place(Line line, const PlannedSegment& segment, uint64_t time) {
  line.json["pts"] = time - segment.start;
  line.json["utc"] = SegmentPlanner::isoUtc(line.unixMs);
  std::string text = line.json.dump();
  auto& sidecar = sidecarOf(segment.path);
  if (!sidecar.write(text) && sidecar.path() != failedPath_) {
    failedPath_ = sidecar.path();
    failure_ = "cannot write " + sidecar.path();
  }
  // A line late for a segment whose file has moved on stays in the sidecar.
  track_.write(text, time, segment.start);
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
  if (dropped_ > 0 && !failure_) {
    failure_ = std::to_string(dropped_) + " telemetry line(s) dropped while no video came (" +
               std::to_string(kMaxWaiting) + " are kept for the next segment)";
    dropped_ = 0;
  }
  return std::exchange(failure_, std::nullopt);
}

}  // namespace wircam::recorder
