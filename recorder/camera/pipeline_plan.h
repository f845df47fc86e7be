// The GStreamer pipeline of a recording, as a gst-launch description, and
// the names of the elements in it that the recorder talks to.
#pragma once

#include <string>
#include <vector>

#include "app/recorder_options.h"

namespace wircam::recorder {

// One device camera: its own pipeline, and the names of its elements
// (empty: not in this run).
struct StreamPlan {
  std::string description;  // gst-launch syntax
  std::string device;       // the device's label, made safe for file names
  int camera = 0;
  std::string name;             // "<device>-cam<N>", also in file names and the live view
  std::string source;           // wircsrc
  std::string muxer;            // splitmuxsink
  std::string telemetrySource;  // appsrc feeding the file's text track
  std::string detector;         // apriltagdetect, with --detect
  std::string controller;       // wirccontrol, on the first camera of a following device
  std::string liveSink;         // appsink of the frames as they arrive, with --http/--rtsp
  std::string positions;        // marvelmindpositions, with --marvelmind
};

struct PipelinePlan {
  std::vector<StreamPlan> streams;
  bool transcoded = false;  // frames pass an encoder that makes key frames on request
  // Every stream's pipeline, one after the other (for reading).
  std::string description() const;
};

// Each stream is a pipeline of its own, so that a camera that never sends a
// frame, errors or stalls holds no other camera's preroll, EOS or stop.
// Per stream: wircsrc → [marvelmindpositions →] tee → queue → [decode → x264enc →] splitmuxsink,
// an appsrc of telemetry text into the same splitmuxsink, and, when asked
// for, a leaky branch to AprilTag detection (→ wirccontrol) and one to an
// appsink for the live view and RTSP. splitmuxsink never cuts on its own:
// the recorder's SegmentSplitter tells it where (and names the files).
PipelinePlan planPipeline(const RecorderOptions& options);

}  // namespace wircam::recorder
