// The frames of one camera as they arrive (JPEG, untouched), handed to the
// live outputs: the web server's MJPEG streams and the RTSP server.
#pragma once

#include <gst/gst.h>

#include <functional>
#include <map>
#include <mutex>

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
  std::mutex mutex_;  // guards listeners_ and nextId_
  std::map<int, Listener> listeners_;
  int nextId_ = 1;
};

}  // namespace wircam::recorder
