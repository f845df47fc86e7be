// One stream's telemetry lines, each written into the segment its time
// falls in: that segment's sidecar and, while its file is being written,
// its text track. So a sidecar and its file's text track describe exactly
// that file, on its own timeline ("pts" counts from its first frame), and
// every line also says when it happened ("utc").
#pragma once

#include <cstdint>
#include <deque>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>

#include "common/mutex.h"
#include "segment_planner.h"
#include "telemetry_log.h"
#include "telemetry_track.h"

namespace wircam::recorder {

class TelemetryRouter {
 public:
  // Both are borrowed.
  TelemetryRouter(const SegmentPlanner& planner, TelemetryTrack& track)
      : planner_(planner), track_(track) {}

  // Thread-safe. Lines from before the first frame (the login, the control
  // right) wait for it, up to kMaxEarlyLines, and then go at pts 0.
  void write(nlohmann::json line, uint64_t runningTime, int64_t unixMs);
  // The first segment began: the lines that waited for it are written.
  void flushEarly();
  // A segment's file was opened: its sidecar exists from then on, even if
  // no line comes.
  void segmentOpened(const std::string& segment);
  // The sidecars a problem was met writing, once each (for the log).
  std::optional<std::string> takeWriteFailure();

  static constexpr size_t kMaxEarlyLines = 256;

 private:
  struct Line {
    nlohmann::json json;
    uint64_t runningTime;
    int64_t unixMs;
  };
  void place(Line line, const PlannedSegment& segment) WIRCAM_REQUIRES(mutex_);
  TelemetryLog& sidecarOf(const std::string& segment) WIRCAM_REQUIRES(mutex_);

  const SegmentPlanner& planner_;
  TelemetryTrack& track_;
  Mutex mutex_;
  std::deque<Line> early_ WIRCAM_GUARDED_BY(mutex_);
  std::deque<std::unique_ptr<TelemetryLog>> sidecars_ WIRCAM_GUARDED_BY(mutex_);  // newest last
  std::optional<std::string> failure_ WIRCAM_GUARDED_BY(mutex_);
  std::string failedPath_ WIRCAM_GUARDED_BY(mutex_);
};

}  // namespace wircam::recorder
