// One WebRTC viewer of a camera: a branch off the camera's encoder (a leaky
// queue → rtpvp8pay or rtph264pay → webrtcbin) that answers the viewer's offer, and the
// data channel the page drives over. Lives on the main loop; webrtcbin's
// promises and signals come on its threads and are handed to the main loop,
// and nothing of them runs once the viewer is gone.
#pragma once

#define GST_USE_UNSTABLE_API  // gst/webrtc's API is marked unstable in 1.22
#include <gst/gst.h>
#include <gst/webrtc/webrtc.h>

#include <atomic>
#include <chrono>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "common/expected.h"
#include "live/ice_servers.h"
#include "webrtc/answer_gathering.h"
#include "webrtc/camera_encoder.h"
#include "webrtc/whep_sdp.h"

namespace wircam::recorder {

class WebRtcViewer {
 public:
  struct Events {
    // Once: the answer (SDP, with every candidate gathered), or why not.
    std::function<void(Expected<std::string, std::string>)> answered;
    // The peer connection failed or closed: the viewer may go.
    std::function<void()> ended;
    // A message on the "drive" data channel (nullopt: a binary one) → the
    // reply to send back (empty: none).
    std::function<std::string(std::optional<std::string_view>)> driveMessage;
    // The drive channel closed (the vehicle goes to neutral).
    std::function<void()> driveClosed;
  };

  WebRtcViewer(CameraEncoder& encoder, const ViewerOffer& offer, const IceServers& servers,
               Events events);
  ~WebRtcViewer();  // its elements leave the encoder's pipeline
  WebRtcViewer(const WebRtcViewer&) = delete;
  WebRtcViewer& operator=(const WebRtcViewer&) = delete;

  // As webrtcbin last told it. Not asked of webrtcbin: a property read waits
  // for the operation it runs, which for the first viewer includes making
  // the DTLS certificate (seconds, on a loaded machine), and the main loop
  // would wait with it (every drive command, every request).
  GstWebRTCPeerConnectionState state() const { return connectionState_; }
  // When the viewer's browser last sent RTCP (its receiver reports, about
  // every second): a viewer silent for long has gone, however it went.
  std::chrono::steady_clock::time_point lastHeard() const;
  // How far its answer got (for the log of one not given in time), and
  // how many candidates of the recorder's it carries or will.
  std::string preparation() const { return gathering_.progress(); }
  int candidatesGathered() const { return gathering_.candidates(); }

 private:
  // What webrtcbin's threads are handed: the viewer, while it lives.
  using Handle = std::weak_ptr<WebRtcViewer*>;
  struct Answering {
    Handle handle;
    GstElement* webrtc;  // a reference of its own
  };
  static void onAnswerCreated(GstPromise* promise, gpointer answering);
  static void onGatheringState(GstElement* webrtc, GParamSpec*, gpointer handle);
  static void onIceCandidate(GstElement*, guint mline, gchar* candidate, gpointer handle);
  static void onConnectionState(GstElement* webrtc, GParamSpec*, gpointer handle);
  static void onDataChannel(GstElement*, GstWebRTCDataChannel* channel, gpointer handle);
  // `call` on the main loop with the viewer, unless it is gone by then.
  static void handOver(gpointer handle, std::function<void(WebRtcViewer&)> call);
  gulong connect(gpointer instance, const char* signal, GCallback callback);
  // H.264 as recorded: the viewer's first frame is an IDR it can start on.
  void startOnAnIdrOnceConnected();
  void negotiate(const std::string& offer);
  void waitForCandidates(const std::string& answer);
  void answerIfGathered(AnswerGathering::Clock::time_point now);
  void finish(Expected<std::string, std::string> answer);
  void openDriveChannel(GstWebRTCDataChannel* channel);

  CameraEncoder& encoder_;
  Events events_;
  GstElement* queue_ = nullptr;
  GstElement* payloader_ = nullptr;
  GstElement* webrtc_ = nullptr;
  GstPad* teePad_ = nullptr;
  int h264Payload_ = -1;          // the recording's H.264 goes out as this
  std::string h264Format_;        // as the offer gave its format
  std::vector<gulong> handlers_;  // on webrtc_
  GstElement* rtpbin_ = nullptr;  // webrtcbin's own
  gulong heardHandler_ = 0;
  // Written on webrtcbin's RTCP thread (steady_clock ticks).
  std::shared_ptr<std::atomic<int64_t>> heard_ = std::make_shared<std::atomic<int64_t>>(
      std::chrono::steady_clock::now().time_since_epoch().count());
  // Host candidates are there at once; STUN and TURN answers take a round
  // trip. An answer that holds a candidate waits this long for them at most.
  static constexpr auto kGatheringPatience = std::chrono::seconds(3);
  // The answer waits for its candidates, which come one by one.
  guint gatherTimer_ = 0;
  AnswerGathering gathering_{kGatheringPatience};
  std::string answer_;
  std::vector<LocalCandidate> candidates_;
  bool answered_ = false;
  GstWebRTCPeerConnectionState connectionState_ = GST_WEBRTC_PEER_CONNECTION_STATE_NEW;
  GstWebRTCDataChannel* drive_ = nullptr;
  std::vector<gulong> driveHandlers_;
  // What webrtcbin's threads hand over checks it: the viewer may be gone.
  std::shared_ptr<WebRtcViewer*> alive_ = std::make_shared<WebRtcViewer*>(this);
};

}  // namespace wircam::recorder
