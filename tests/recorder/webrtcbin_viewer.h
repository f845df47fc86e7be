// A WebRTC viewer we did not write: GStreamer's webrtcbin receiving video,
// offering the given codecs in their order, its H.264 depayloaded and
// decoded by avdec_h264. It counts the frames decoded and keeps the first
// access unit it received (Annex B), to tell whether a decoder could start
// on it.
#pragma once

#include <gst/gst.h>

#include <atomic>
#include <string>

#include "common/mutex.h"

namespace wircam::testing {

// Constrained Baseline (108) before Main (116).
constexpr const char* kBaselineThenMain =
    "application/x-rtp,media=video,encoding-name=H264,payload=108,clock-rate=90000,"
    "packetization-mode=(string)1,profile-level-id=(string)42e01f,"
    "level-asymmetry-allowed=(string)1;"
    "application/x-rtp,media=video,encoding-name=H264,payload=116,clock-rate=90000,"
    "packetization-mode=(string)1,profile-level-id=(string)4d001f,"
    "level-asymmetry-allowed=(string)1";

// VP8 (96) before Main (102), as a stranger's webrtcbin client offered.
constexpr const char* kVp8ThenMain =
    "application/x-rtp,media=video,encoding-name=VP8,payload=96,clock-rate=90000;"
    "application/x-rtp,media=video,encoding-name=H264,payload=102,clock-rate=90000,"
    "packetization-mode=(string)1,profile-level-id=(string)4d001f,"
    "level-asymmetry-allowed=(string)1";

class WebRtcBinViewer {
 public:
  explicit WebRtcBinViewer(const char* codecs = kBaselineThenMain);
  ~WebRtcBinViewer();
  WebRtcBinViewer(const WebRtcBinViewer&) = delete;
  WebRtcBinViewer& operator=(const WebRtcBinViewer&) = delete;

  // The offer, once its candidates are gathered.
  std::string offer();
  void answer(const std::string& sdp);
  int decoded() const { return decoded_; }
  // The first H.264 access unit depayloaded, Annex B; empty until one came.
  std::string firstAccessUnit() const;

 private:
  static void onPad(GstElement*, GstPad* pad, WebRtcBinViewer* self);

  GstElement* pipeline_ = nullptr;
  GstElement* webrtc_ = nullptr;
  std::atomic<int> decoded_ = 0;
  mutable Mutex mutex_;  // the first unit is kept on a streaming thread
  std::string firstAccessUnit_ WIRCAM_GUARDED_BY(mutex_);
};

}  // namespace wircam::testing
