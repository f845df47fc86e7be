// The telemetry as a timed text track inside the recording: each JSON line
// becomes one UTF-8 text buffer at the running time it belongs to.
#pragma once

#include <gst/gst.h>

#include <string>

namespace wircam::recorder {

class TelemetryTrack {
 public:
  // `source` is the stream's appsrc (text/x-raw, format=utf8); borrowed.
  explicit TelemetryTrack(GstElement* source) : source_(source) {}

  // A muxer wants the timestamps of a track to rise, but events arrive a
  // little out of order (a detection is stamped with its frame's time, a
  // little after later statistics). Such a line is placed at the latest
  // time already written; its own "pts" field keeps the exact time.
  void write(const std::string& json, GstClockTime pts);

 private:
  GstElement* source_;
  GstClockTime last_ = 0;
};

}  // namespace wircam::recorder
