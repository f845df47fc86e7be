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

#include "camera/frame_tap.h"
#include "common/expected.h"
#include "live/live_servers.h"
#include "live/server_address.h"

namespace wircam::recorder {

class RtspServer : public RtspService {
 public:
  using Camera = RtspCamera;

  // With a token every request needs it (rtsp_token_auth.h).
  static Expected<std::unique_ptr<RtspServer>, std::string> start(const ServerAddress& address,
                                                                  std::vector<Camera> cameras,
                                                                  const std::string& token = "");
  ~RtspServer() override;

  const std::string& url() const override { return url_; }
  void addCamera(const RtspCamera& camera) override;
  void removeCamera(const std::string& path) override;

 private:
  struct Mount;
  RtspServer() = default;
  static void onMediaConfigure(GstRTSPMediaFactory*, GstRTSPMedia* media, gpointer mount);

  GstRTSPServer* server_ = nullptr;
  guint source_ = 0;
  std::string url_;
  std::string token_;
  std::vector<std::unique_ptr<Mount>> mounts_;
};

}  // namespace wircam::recorder
