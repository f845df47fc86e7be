// The GStreamer pipeline of a recording, as a gst-launch description, and
// the names of the elements in it that the recorder talks to (planned from
// the options by app/pipeline_planner.h).
#pragma once

#include <string>
#include <utility>
#include <vector>

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
  bool operator==(const MuxerSpec&) const = default;
};

// Each file's muxer as the recorder writes it, its text track included
// (`text`: turn it off for none).
MuxerSpec matroskaMuxer();
MuxerSpec mp4Muxer();

// One device camera: its own pipeline, and the names of its elements
// (empty: not in this run).
struct StreamPlan {
  std::string description;  // gst-launch syntax
  std::string device;       // the device's label, made safe for file names
  std::string host;         // the device's control address (empty: found by discovery)
  uint16_t port = 0;
  int camera = 0;
  std::string name;    // "<device>-cam<N>", also in file names and the live view
  std::string source;  // wircsrc
  // The encoder's first element: frames are planned into files (or
  // dropped for the disk) as they enter it. Empty: as they leave videoTail.
  std::string planPoint;
  // How much of the camera's video may wait for its disk's writer, in
  // bytes (camera/disk_writer.h); past it frames are dropped and counted.
  // 0: the files are written on the stream's own thread (a filesink).
  uint64_t recordBound = 0;
  std::string videoTail;  // the last element before the files' muxer (a tee: a new pad)
  // The files' text track (empty: none): its appsrc (MP4; with Matroska
  // the frames' thread feeds the tail), and the last element before the
  // muxer.
  std::string telemetrySource;
  std::string telemetryTail;
  MuxerSpec muxer;         // each file's
  std::string detector;    // apriltagdetect, with --detect
  std::string controller;  // wirccontrol, on the first camera of a following device
  std::string liveSink;    // appsink of the frames as they arrive, with --http/--rtsp
  std::string positions;   // marvelmindpositions, with --marvelmind
  bool operator==(const StreamPlan&) const = default;
};

struct PipelinePlan {
  std::vector<StreamPlan> streams;
  bool transcoded = false;  // frames pass an encoder that makes key frames on request
  // Every stream's pipeline, one after the other (for reading).
  std::string description() const;
};

}  // namespace wircam::recorder
