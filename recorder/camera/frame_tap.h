// The frames of one camera as they arrive (JPEG, untouched), handed to the
// live outputs: the web server's MJPEG streams, the RTSP server and WebRTC;
// or, for a recording encoded to H.264, its H.264 frames, for WebRTC. It
// outlives the camera's pipelines: each run's appsink is attached in turn,
// and the listeners stay.
#pragma once

#include <gst/gst.h>

#include <functional>
#include <map>

#include "common/mutex.h"

namespace wircam::recorder {

class FrameTap {
 public:
  // Called on the streaming thread with a borrowed frame and its caps (the
  // size from the JPEG's SOF); take a reference to keep it. Keep it short:
  // the branch drops frames while it runs.
  using Listener = std::function<void(GstSample* jpeg)>;

  FrameTap() = default;
  FrameTap(const FrameTap&) = delete;
  FrameTap& operator=(const FrameTap&) = delete;
  ~FrameTap();

  // `appsink` is the live branch of the camera's running pipeline; borrowed
  // until detach(), which comes before the pipeline goes.
  void attach(GstElement* appsink);
  // Or a pad of it: each buffer that passes is handed on, with the pad's
  // caps, on the pad's thread (the recording's H.264, as it goes to the file).
  void attachPad(GstPad* pad);
  void detach();

  int listen(Listener listener);
  void forget(int id);
  // The newest frame (a reference to unref), or null before the first.
  GstBuffer* latest();
  // When a frame handed to a listener arrived, as Unix nanoseconds: its
  // running time (wircsrc stamps a frame with the kernel's receive time of
  // its first datagram) on the pipeline's clock, as the recording's times
  // are; now when it carries none. Only from within a listener's call.
  int64_t wallTimeNs(GstSample* sample) const;

 private:
  static GstFlowReturn onNewSample(GstElement* appsink, gpointer self);
  void hand(GstSample* sample);

  GstElement* appsink_ = nullptr;
  gulong handler_ = 0;
  GstPad* pad_ = nullptr;
  gulong probe_ = 0;
  Mutex mutex_;
  std::map<int, Listener> listeners_ WIRCAM_GUARDED_BY(mutex_);
  int nextId_ WIRCAM_GUARDED_BY(mutex_) = 1;
  GstBuffer* latest_ WIRCAM_GUARDED_BY(mutex_) = nullptr;
};

}  // namespace wircam::recorder
