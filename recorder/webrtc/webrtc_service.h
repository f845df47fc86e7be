// The recorder's WebRTC live view: each camera encoded once while someone
// watches it, its viewers (each a WHEP session), and their end: a DELETE of
// the session, a connection that fails or closes, one that is not up within
// the idle timeout (a viewer gone mid-negotiation), or one whose browser
// sent no RTCP for that long (a closed tab, a lost network). At most
// kMaxViewers at once, so memory and threads stay bounded.
#pragma once

#include <glib.h>

#include <chrono>
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <set>
#include <string>
#include <string_view>
#include <vector>

#include "camera/frame_tap.h"
#include "common/expected.h"
#include "webrtc/camera_encoder.h"
#include "webrtc/webrtc_viewer.h"

namespace wircam::recorder {

class WebRtcService {
 public:
  struct Camera {
    std::string name;
    FrameTap* frames;          // its JPEG frames; borrowed, outlives the service
    FrameTap* h264 = nullptr;  // its recording's H.264 (--codec h264), or null
  };
  struct Settings {
    IceServers servers;
    unsigned kbps = 600;  // each camera's VP8 (H.264 goes as recorded)
    std::chrono::milliseconds idleTimeout{10000};
    // A drive data channel's message for `camera` → the reply (driving
    // done, see drive_command.h); and the channel's end → neutral.
    std::function<std::string(const std::string& camera, std::optional<std::string_view>)>
        driveMessage;
    std::function<void(const std::string& camera)> neutral;
  };
  // Each viewer is a webrtcbin with its own ICE, DTLS and SCTP threads.
  static constexpr size_t kMaxViewers = 32;

  // The GStreamer elements WebRTC needs that are not installed (webrtcbin
  // and ICE: gstreamer1.0-plugins-bad and gstreamer1.0-nice), by name.
  static std::vector<std::string> missingElements();

  WebRtcService(std::vector<Camera> cameras, Settings settings);
  ~WebRtcService();
  WebRtcService(const WebRtcService&) = delete;
  WebRtcService& operator=(const WebRtcService&) = delete;

  struct Answer {
    std::string sdp;
    std::string session;  // for the Location: /api/cameras/CAMERA/whep/SESSION
  };
  struct Refusal {
    unsigned status;  // HTTP
    std::string why;
  };
  using Done = std::function<void(Expected<Answer, Refusal>)>;
  // A viewer's offer for `camera` from `viewerAddress` (the HTTP peer's IP:
  // only candidates for it are kept). `done` is called once on the main
  // loop, maybe before this returns.
  void offer(const std::string& camera, std::string_view sdp, const std::string& viewerAddress,
             Done done);
  // A camera a reload added, or removed (its viewers let go).
  void addCamera(Camera camera);
  void removeCamera(const std::string& name);
  // Ends a session (WHEP's DELETE); false if there is none such.
  bool end(const std::string& camera, const std::string& session);
  size_t viewers() const { return viewers_.size(); }
  size_t encoders() const { return encoders_.size(); }

  // Releases the viewers not connected, or silent, for longer than the idle
  // timeout at `now` (not connected: counted from their answer); the
  // service's own timer calls it twice a second.
  void sweep(std::chrono::steady_clock::time_point now);

 private:
  struct Viewer {
    std::string camera;
    std::string encoder;  // its key in encoders_
    std::unique_ptr<WebRtcViewer> peer;
    std::optional<std::chrono::steady_clock::time_point> downSince;  // not connected since
    Done unanswered;  // the offer's request, until the viewer answers it
  };
  void remove(const std::string& session);
  void removeLater(const std::string& session);
  // Offers again those that waited for the DTLS certificate, once it is made.
  static gboolean offerWhenCertified(gpointer self);
  const Camera* cameraNamed(const std::string& name) const;

  std::vector<Camera> cameras_;
  Settings settings_;
  std::set<std::string> allowedHosts_;  // the TURN server's, besides each viewer's own
  // By camera and codec ("rover-cam0 vp8"): a camera can have both at once.
  std::map<std::string, std::unique_ptr<CameraEncoder>> encoders_;
  std::map<std::string, Viewer> viewers_;  // by session
  guint sweepTimer_ = 0;
  struct WaitingOffer {
    std::string camera, sdp, viewerAddress;
    Done done;
  };
  std::vector<WaitingOffer> waitingForCertificate_;
  guint certificateCheck_ = 0;
  std::shared_ptr<WebRtcService*> alive_ = std::make_shared<WebRtcService*>(this);
};

}  // namespace wircam::recorder
