// The GStreamer pipeline of a recording, as a gst-launch description, and
// the names of the elements in it that the recorder talks to.
#pragma once

#include <string>
#include <vector>

#include "recorder_options.h"

namespace wircam::recorder {

// One device camera: its branches are named after `index`.
struct StreamPlan {
  std::string device;  // the device's label, made safe for file names
  int camera = 0;
  std::string name;  // "<device>-cam<N>", also in file names and the live view
  std::string muxer;            // splitmuxsink
  std::string telemetrySource;  // appsrc feeding the file's text track; empty for MP4
  std::string liveSink;         // appsink of the frames as they arrive, or empty
};

struct PipelinePlan {
  std::string description;
  std::vector<StreamPlan> streams;
};

// Per stream: wircsrc → tee → queue → [decode → x264enc →] splitmuxsink,
// an appsrc of telemetry text into the same splitmuxsink, and, when asked
// for, a leaky branch to AprilTag detection (→ wirccontrol) and one to an
// appsink for the live view and RTSP. `startTime` goes into file names.
PipelinePlan planPipeline(const RecorderOptions& options, const std::string& startTime);

}  // namespace wircam::recorder
