// One wirc-recorder run: a GStreamer pipeline with, per device and camera,
// wircsrc → splitmuxsink (JPEG frames muxed as they arrive) and, with
// --detect, a branch through tjpegdec → apriltagdetect (→ wirccontrol),
// plus the telemetry sidecars and the status display fed from the bus.
#pragma once

#include <gst/gst.h>

#include <memory>
#include <string>
#include <vector>

#include "common/expected.h"
#include "recorder_options.h"
#include "retention.h"
#include "telemetry_log.h"

namespace wircam::recorder {

class Recording {
 public:
  static Expected<std::unique_ptr<Recording>, std::string> create(const RecorderOptions& options);
  ~Recording();

  // Records until SIGINT/SIGTERM, --duration or an error; every file is
  // finished before it returns. The process exit code.
  int run();

 private:
  struct Stream {
    std::string name;   // "<device>-cam<N>"
    std::string muxer;  // its splitmuxsink's element name
    TelemetryLog telemetry;
    std::string segment;
    guint64 frames = 0, incomplete = 0, bytes = 0;
    guint64 lastFrames = 0, lastBytes = 0;
    guint batteryMv = 0;
    bool lost = false;  // the device went away; the next login starts a segment
  };

  explicit Recording(RecorderOptions options);
  static gboolean onBusMessage(GstBus* bus, GstMessage* message, gpointer self);
  static gboolean onStop(gpointer self);
  static gboolean onStatus(gpointer self);
  void handleElementMessage(GstMessage* message);
  void printStatus();
  Stream* streamOf(GstMessage* message);

  RecorderOptions options_;
  Retention retention_;
  GstElement* pipeline_ = nullptr;
  GMainLoop* loop_ = nullptr;
  std::vector<std::unique_ptr<Stream>> streams_;
  bool stopping_ = false;
  int exitCode_ = 0;
  bool statusShown_ = false;
};

}  // namespace wircam::recorder
