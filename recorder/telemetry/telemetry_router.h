// One stream's telemetry lines, each written into the segment its time
// falls in: that segment's sidecar and, while its file is being written,
// its text track. So a sidecar and its file's text track describe exactly
// that file, on its own timeline ("pts" counts from its first frame), and
// every line also says when it happened ("utc").
//
// No file holds a line past its last frame: a line newer than the newest
// frame waits for the next one. If the video goes on in the same file it is
// written at its own time; if the next frame opens a new file (the device
// was lost meanwhile, or the segment was full), it goes at that file's
// start, pts 0, as the lines from before the first frame do.
#pragma once

#include <cstdint>
#include <deque>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>

#include "common/mutex.h"
#include "record/segment_planner.h"
#include "record/telemetry_log.h"
#include "telemetry/telemetry_track.h"

namespace wircam::recorder {

class TelemetryRouter {
 public:
  // Both are borrowed.
  TelemetryRouter(const SegmentPlanner& planner, TelemetryTrack& track)
      : planner_(planner), track_(track) {}

  // Thread-safe. A line past the newest frame waits (up to kMaxWaiting
  // lines; older ones are dropped first, and counted).
  void write(nlohmann::json line, uint64_t runningTime, int64_t unixMs);
  // A frame was planned (on the source's thread): the lines it reaches are
  // written.
  void onFrame();
  // The recording stops: the waiting lines, and any to come, are written
  // into the newest file, at its last frame at the latest.
  void finish();

  struct Line {
    nlohmann::json json;
    uint64_t runningTime;
    int64_t unixMs;
  };
  // The camera's pipeline is to start again: the lines that wait for a
  // frame (past the files' end) are handed back, for the next run's first
  // file (where they open its sidecar at pts 0, with their own "utc").
  std::deque<Line> handOver();
  // A segment's file was opened: its sidecar exists from then on, even if
  // no line comes.
  void segmentOpened(const std::string& segment);
  // The sidecars a problem was met writing, and lines dropped while the
  // video was away, once each (for the log).
  std::optional<std::string> takeWriteFailure();

  static constexpr size_t kMaxWaiting = 1024;

 private:
  // Into `segment` at `time` (within its span).
  void place(Line line, const PlannedSegment& segment, uint64_t time) WIRCAM_REQUIRES(mutex_);
  void writeWaiting() WIRCAM_REQUIRES(mutex_);
  // Once no frame will come: into the segment its time falls in, at that
  // segment's last frame at the latest.
  void placeByItsLastFrame(Line line) WIRCAM_REQUIRES(mutex_);
  TelemetryLog& sidecarOf(const std::string& segment) WIRCAM_REQUIRES(mutex_);

  const SegmentPlanner& planner_;
  TelemetryTrack& track_;
  Mutex mutex_;
  std::deque<Line> waiting_ WIRCAM_GUARDED_BY(mutex_);  // oldest first
  uint64_t dropped_ WIRCAM_GUARDED_BY(mutex_) = 0;      // since the last report
  bool finished_ WIRCAM_GUARDED_BY(mutex_) = false;
  std::deque<std::unique_ptr<TelemetryLog>> sidecars_ WIRCAM_GUARDED_BY(mutex_);  // newest last
  std::optional<std::string> failure_ WIRCAM_GUARDED_BY(mutex_);
  std::string failedPath_ WIRCAM_GUARDED_BY(mutex_);
};

}  // namespace wircam::recorder
