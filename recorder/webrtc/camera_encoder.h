// One camera's frames encoded once for all of its WebRTC viewers: its JPEG
// frames (from the camera's FrameTap) → tjpegdec → vp8enc, in real time and
// without look-ahead, → a tee that each viewer branches off; or, for a
// recording in H.264, the recording's own frames passed through to the tee
// without encoding again. A pipeline of its own, apart from the camera's
// recording: it runs only while someone watches, and a viewer's trouble
// never reaches the files.
#pragma once

#include <gst/gst.h>

#include <memory>
#include <string>

#include "camera/frame_tap.h"
#include "common/expected.h"

namespace wircam::recorder {

// What the viewers get: VP8 encoded here, or the recording's H.264.
enum class WebRtcVideo { kVp8, kH264 };

class CameraEncoder {
 public:
  // Starts on the frames `frames` hands over (borrowed; it outlives the
  // encoder): JPEG encoded to VP8 at about `kbps`, or H.264 passed through.
  static Expected<std::unique_ptr<CameraEncoder>, std::string> start(FrameTap& frames,
                                                                     const std::string& camera,
                                                                     WebRtcVideo video,
                                                                     unsigned kbps);
  ~CameraEncoder();  // stops listening, then the pipeline
  CameraEncoder(const CameraEncoder&) = delete;
  CameraEncoder& operator=(const CameraEncoder&) = delete;

  // Where viewers' branches go, and the tee (video/x-vp8) they link to.
  GstBin* pipeline() const { return GST_BIN(pipeline_); }
  GstElement* tee() const { return tee_; }
  WebRtcVideo video() const { return video_; }
  // Lets go of what the pipeline's messages still hold: a viewer's gone
  // webrtcbin stays alive, with its threads and sockets, until they go
  // (measured with GStreamer 1.22; a flushing bus alone does not do it).
  void releaseMessages();

 private:
  CameraEncoder() = default;

  FrameTap* frames_ = nullptr;
  int listener_ = 0;
  GstElement* pipeline_ = nullptr;
  GstElement* source_ = nullptr;  // appsrc
  GstElement* tee_ = nullptr;
  WebRtcVideo video_ = WebRtcVideo::kVp8;
};

}  // namespace wircam::recorder
