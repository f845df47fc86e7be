// One viewer's replay of a recorded Matroska segment as MJPEG, at real
// speed from a given offset: the camera's JPEG frames as they were stored
// (no transcode), each with its position in the segment. A pipeline of
// GStreamer's own elements (filesrc, matroskademux, appsink synced to the
// clock); frames and the end come on the main loop.
#pragma once

#include <gst/gst.h>

#include <functional>
#include <memory>
#include <string>

#include "common/expected.h"

namespace wircam::recorder {

class PlaybackStream {
 public:
  struct Callbacks {
    // A frame and its position in the segment, seconds (main loop).
    std::function<void(GstBuffer* jpeg, double position)> frame;
    // The segment ended, or could not be read (`error` says why).
    std::function<void(const std::string& error)> ended;
  };
  // Why a replay cannot start: the file holds no JPEG video (or cannot be
  // read), or `fromSeconds` is at or past its end.
  struct Refusal {
    bool pastTheEnd = false;
    std::string text;
  };
  // Starts at the frame at `fromSeconds`.
  static Expected<std::unique_ptr<PlaybackStream>, Refusal> start(const std::string& path,
                                                                  double fromSeconds,
                                                                  Callbacks callbacks);
  ~PlaybackStream();
  PlaybackStream(const PlaybackStream&) = delete;
  PlaybackStream& operator=(const PlaybackStream&) = delete;

 private:
  explicit PlaybackStream(Callbacks callbacks);
  static GstFlowReturn onSample(GstElement* sink, gpointer self);
  static gboolean onBusMessage(GstBus*, GstMessage* message, gpointer self);

  Callbacks callbacks_;
  GstElement* pipeline_ = nullptr;
  guint busWatch_ = 0;
  // Frames on their way to the main loop check it: the stream may be gone.
  std::shared_ptr<bool> alive_ = std::make_shared<bool>(true);
};

}  // namespace wircam::recorder
