// Where one stream's segments begin, decided from the frames as they come
// out of the source, before any queue: a segment ends at its length, at its
// byte limit, or at a gap in the frames (the device was lost), and the next
// begins with the frame after. Deciding this up front (rather than learning
// it from the muxer a GOP later) is what lets every telemetry line be
// written into the segment its time falls in the moment it is written.
//
// GStreamer-free: times are pipeline running times in nanoseconds, wall
// clock times Unix milliseconds. Thread-safe: frames come on the source's
// streaming thread, bytes on the muxer's, look-ups on the main loop.
#pragma once

#include <cstdint>
#include <filesystem>
#include <functional>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include "common/mutex.h"

namespace wircam::recorder {

struct PlannedSegment {
  std::string path;         // the video file
  int64_t startUnixMs = 0;  // wall clock time of its first frame
  uint64_t start = 0;       // running time of its first frame
  uint64_t lastFrame = 0;   // running time of its last frame so far
  uint64_t frames = 0;
  uint64_t bytes = 0;  // what reached the muxer, counted toward the byte limit
  // How long the file plays: its frames' span and one frame period more.
  double durationSeconds() const;
};

struct SegmentLimits {
  uint64_t maxDuration = 0;       // ns; 0 = none
  uint64_t maxBytes = 0;          // 0 = none
  uint64_t maxGap = 500'000'000;  // ns between two frames inside one file
  bool operator==(const SegmentLimits&) const = default;
};

class SegmentPlanner {
 public:
  // Files are named `<folder>/<stem>-YYYYMMDDTHHMMSSZ<extension>` after the
  // UTC time of their first frame, with "-2", "-3"... only when a file of
  // that name exists already.
  SegmentPlanner(std::filesystem::path folder, std::string stem, std::string extension,
                 SegmentLimits limits);

  enum class Cut { kNone, kFirst, kNext };
  // A frame left the source at running time `pts`. kFirst: it opens the
  // first segment; kNext: it ends the current segment and opens another
  // (the caller has the muxer split there). `unixMsNow` (the frame's wall
  // clock time, for the name) is asked only when a segment opens.
  Cut onFrame(uint64_t pts, const std::function<int64_t()>& unixMsNow);
  // Bytes of the current segment reached the muxer; past the limit, the
  // next frame starts a new segment.
  void addBytes(uint64_t bytes);
  // The recording is stopping: the frames still coming until it ends join
  // the open segment past its length, so a stop never opens a file of a
  // frame or two. (The byte limit and a gap still cut.)
  void finishing();

  // The segment a time belongs to: the last that started at or before it
  // (times before the first frame belong to the first segment).
  std::optional<PlannedSegment> segmentAt(uint64_t runningTime) const;
  // Where a telemetry line of `runningTime` goes once the video has caught
  // up with it: the first segment whose last frame so far is at or after it
  // (a time before that segment's first frame, in the gap of an outage or
  // before the first frame, lands on its start). nullopt while the time is
  // past the newest frame: no file may hold anything after its last frame.
  std::optional<PlannedSegment> segmentReaching(uint64_t runningTime) const;
  std::optional<PlannedSegment> segmentOf(const std::string& path) const;
  std::optional<PlannedSegment> current() const;

  // "20261122T143205Z", the form file names use.
  static std::string compactUtc(int64_t unixMs);
  // "2026-11-22T14:32:05.123Z", the form telemetry and the index use.
  static std::string isoUtc(int64_t unixMs);

 private:
  std::string nameFor(int64_t unixMs) WIRCAM_REQUIRES(mutex_);

  const std::filesystem::path folder_;
  const std::string stem_, extension_;
  const SegmentLimits limits_;
  mutable Mutex mutex_;
  std::vector<PlannedSegment> segments_ WIRCAM_GUARDED_BY(mutex_);  // the newest last
  std::set<std::string> used_ WIRCAM_GUARDED_BY(mutex_);            // names given out
  bool splitPending_ WIRCAM_GUARDED_BY(mutex_) = false;             // the byte limit was reached
  bool finishing_ WIRCAM_GUARDED_BY(mutex_) = false;                // the length no longer cuts
  // Past segments kept for look-ups of late telemetry and closing files.
  static constexpr size_t kKept = 16;
};

}  // namespace wircam::recorder
