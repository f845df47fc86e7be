// The frames of one camera as they arrive (JPEG, untouched), handed to the
// live outputs: the web server's MJPEG streams and the RTSP server.
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

  // `appsink` is the camera's live branch; borrowed, must outlive the tap.
  explicit FrameTap(GstElement* appsink);
  FrameTap(const FrameTap&) = delete;
  FrameTap& operator=(const FrameTap&) = delete;
  ~FrameTap();

  int listen(Listener listener);
  void forget(int id);

 private:
  static GstFlowReturn onNewSample(GstElement* appsink, gpointer self);

  GstElement* appsink_;
  gulong handler_ = 0;
  Mutex mutex_;
  std::map<int, Listener> listeners_ WIRCAM_GUARDED_BY(mutex_);
  int nextId_ WIRCAM_GUARDED_BY(mutex_) = 1;
};

}  // namespace wircam::recorder
