// The GStreamer pipeline of a recording, as a gst-launch description, and
// the names of the elements in it that the recorder talks to.
#pragma once

#include <string>
#include <utility>
#include <vector>

#include "app/recorder_options.h"

namespace wircam::recorder {

// The muxer each file of a stream is written with, and its settings.
struct MuxerSpec {
  std::string factory;  // "matroskamux", "mp4mux"
  // Name and value, as gst-launch reads them.
  std::vector<std::pair<std::string, std::string>> properties;
  // A gap reaches the muxer as a GAP event (matroskamux writes nothing for
  // it), or as an empty buffer (mp4mux stalls on GAP events).
  bool textGapEvents = false;
  bool text = true;  // the file has the telemetry text track
};

// One device camera: its own pipeline, and the names of its elements
// (empty: not in this run).
struct StreamPlan {
  std::string description;  // gst-launch syntax
  std::string device;       // the device's label, made safe for file names
  int camera = 0;
  std::string name;             // "<device>-cam<N>", also in file names and the live view
  std::string source;           // wircsrc
  std::string videoTail;        // the last element before the files' muxer (a tee: a new pad)
  std::string telemetrySource;  // appsrc of the files' text track (empty: no track)
  std::string telemetryTail;    // the last element before the muxer on the text track
  MuxerSpec muxer;              // each file's
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
// Per stream: wircsrc → [marvelmindpositions →] [tee →] [decode → x264enc →]
// (the file), an appsrc of telemetry text → (the same file, unless
// --telemetry-track off) and, when asked
// for, a leaky branch off the tee to AprilTag detection (→ wirccontrol) and
// one to an appsink for the live view and RTSP. The files themselves (a
// muxer and a filesink each) are not in the description: the recorder's
// SegmentWriter puts each in at its first frame and takes it out when it is
// finished. No queue where nothing branches: the frames reach the file on
// the source's own thread.
PipelinePlan planPipeline(const RecorderOptions& options);

}  // namespace wircam::recorder
