// The appsrcs of one camera's RTSP media, fed the camera's frames on its
// streaming thread. Clients share a media, so there is one while the
// camera is played; another comes in while the last is going.
#pragma once

#include <gst/gst.h>

#include <vector>

#include "common/mutex.h"

namespace wircam::recorder {

// The source at the head of each media: it stamps a frame with the media's
// own clock as it takes it (a client may start at any frame: every JPEG is
// a key frame).
constexpr char kRtspFrameSource[] =
    "appsrc name=frames is-live=true format=time do-timestamp=true "
    "max-bytes=2000000 leaky-type=downstream";

class RtspMediaFeed {
 public:
  RtspMediaFeed() = default;
  RtspMediaFeed(const RtspMediaFeed&) = delete;
  RtspMediaFeed& operator=(const RtspMediaFeed&) = delete;
  ~RtspMediaFeed();

  // A new media's source (a reference is taken).
  void add(GstElement* source);
  // The sources of a media that is going (inside `bin`).
  void removeWithin(GstElement* bin);
  // Hands a frame (borrowed) to each source whose media is PLAYING.
  void push(GstSample* sample);
  // The stream ends for every client: the camera is gone.
  void end();

 private:
  Mutex mutex_;
  std::vector<GstElement*> sources_ WIRCAM_GUARDED_BY(mutex_);
};

}  // namespace wircam::recorder
