// The telemetry as a timed text track inside the recording: each JSON line
// becomes one UTF-8 text buffer at the running time it belongs to.
#pragma once

#include <gst/gst.h>

#include <functional>
#include <string>

#include "common/mutex.h"

namespace wircam::recorder {

class TelemetryTrack {
 public:
  // `source` is the stream's appsrc (text/x-raw, format=utf8); borrowed.
  explicit TelemetryTrack(GstElement* source) : source_(source) {}

  // A muxer wants the timestamps of a track to rise, but events arrive a
  // little out of order (a detection is stamped with its frame's time, a
  // little after later statistics). Such a line is placed at the latest
  // time already written; its own "pts" field keeps the exact time.
  // `tooLate`, asked with the newest buffer's time under the same lock as
  // the heartbeats, may refuse it (the file has moved on): then nothing is
  // written.
  void write(const std::string& json, GstClockTime pts,
             const std::function<bool(GstClockTime newest)>& tooLate = {});

  // An empty buffer, sent every kHeartbeatInterval at the newest frame's
  // time. splitmuxsink hands a GOP to the muxer only once every track's
  // input has passed its end, so a sparse track would hold the video back
  // (and mp4mux waits for every track): this tells both that the telemetry
  // has nothing before `frameTime`. (From a timer rather than with each
  // frame: a GOP is one frame in JPEG, and each heartbeat costs a few
  // thread wake-ups. Not ahead of the video: the text would only wait in
  // splitmuxsink for it.)
  void heartbeat(GstClockTime frameTime) { write({}, frameTime); }
  static constexpr GstClockTime kHeartbeatInterval = GST_SECOND / 8;

 private:
  GstElement* source_;
  mutable Mutex mutex_;  // lines and heartbeats come from the main loop, early lines from streaming
  GstClockTime last_ WIRCAM_GUARDED_BY(mutex_) = 0;
};

}  // namespace wircam::recorder
