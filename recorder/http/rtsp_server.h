// wirc-recorder's RTSP server (gst-rtsp-server): each camera's frames as
// they arrive, payloaded as RTP/JPEG (RFC 2435, no transcode), at
// rtsp://HOST:PORT/<device>/cam<N>. All clients of a camera share one
// media pipeline fed from the camera's FrameTap.
#pragma once

#include <gst/rtsp-server/rtsp-server.h>

#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "app/recorder_options.h"
#include "camera/frame_tap.h"
#include "common/expected.h"

namespace wircam::recorder {

class RtspServer {
 public:
  struct Camera {
    std::string path;  // "/<device>/cam<N>"
    FrameTap* frames;  // borrowed; outlives the server
  };

  // With a token every request needs it (rtsp_token_auth.h).
  static Expected<std::unique_ptr<RtspServer>, std::string> start(const ServerAddress& address,
                                                                  std::vector<Camera> cameras,
                                                                  const std::string& token = "");
  ~RtspServer();

  // "rtsp://HOST:PORT", the port the system picked for port 0.
  const std::string& url() const { return url_; }

 private:
  struct Mount;
  RtspServer() = default;
  static void onMediaConfigure(GstRTSPMediaFactory*, GstRTSPMedia* media, gpointer mount);

  GstRTSPServer* server_ = nullptr;
  guint source_ = 0;
  std::string url_;
  std::vector<std::unique_ptr<Mount>> mounts_;
};

}  // namespace wircam::recorder
