#include "webrtc/webrtc_viewer.h"

#include <gst/sdp/sdp.h>

#include "gst_h264_start.h"
#include "webrtc/main_loop_call.h"

namespace wircam::recorder {

namespace {

// The service made sure at start that each of these is installed.
GstElement* make(const char* factory) {
  GstElement* element = gst_element_factory_make(factory, nullptr);
  if (!element) g_error("wirc-recorder: the %s element is missing", factory);
  return element;
}

// The caps of `payload` on the offer's video m-line, its format parameters
// included; nothing if the offer does not parse (it did before).
GstCaps* offeredCaps(const ViewerOffer& offer, int payload) {
  GstSDPMessage* sdp = nullptr;
  if (gst_sdp_message_new_from_text(offer.sdp.c_str(), &sdp) != GST_SDP_OK) return nullptr;
  GstCaps* caps = nullptr;
  if (const GstSDPMedia* media = gst_sdp_message_get_media(sdp, offer.videoMedia)) {
    caps = gst_sdp_media_get_caps_from_media(media, payload);
    if (caps) {
      caps = gst_caps_make_writable(caps);
      GstStructure* structure = gst_caps_get_structure(caps, 0);
      gst_structure_set_name(structure, "application/x-rtp");
      gst_structure_set(structure, "media", G_TYPE_STRING, "video", "payload", G_TYPE_INT, payload,
                        nullptr);
      // What the stream itself says (its level, its parameter sets) comes
      // from the payloader's caps; a level the offer named would not
      // intersect with them.
      gst_structure_remove_fields(structure, "profile-level-id", "sprop-parameter-sets", nullptr);
    }
  }
  gst_sdp_message_free(sdp);
  return caps;
}

// libnice asks the LAN's router for a UPnP port mapping for every agent
// (webrtcbin leaves it on): a context manager, an HTTP server and SSDP
// searches a viewer, which WebRTC has no use for (its candidates and STUN
// or TURN reach the viewer). Twenty viewers at once fought over ports
// ("gupnp-context: Unable to listen on ...") and kept memory after them.
void withoutUpnp(GstWebRTCICE* ice) {
  if (!ice || !g_object_class_find_property(G_OBJECT_GET_CLASS(ice), "agent")) return;
  GObject* agent = nullptr;
  g_object_get(ice, "agent", &agent, nullptr);
  if (agent && g_object_class_find_property(G_OBJECT_GET_CLASS(agent), "upnp"))
    g_object_set(agent, "upnp", FALSE, nullptr);
  if (agent) g_object_unref(agent);
}

}  // namespace

void WebRtcViewer::handOver(gpointer handle, std::function<void(WebRtcViewer&)> call) {
  Handle viewer = *static_cast<Handle*>(handle);
  // The shared pointer only says whether the viewer lives; it is read on the
  // main loop, where the viewer is deleted.
  std::weak_ptr<void> alive = viewer;
  callOnMainLoop(std::move(alive), [viewer, call = std::move(call)] {
    if (auto self = viewer.lock()) call(**self);
  });
}

gulong WebRtcViewer::connect(gpointer instance, const char* signal, GCallback callback) {
  // Each handler owns its handle: a handler that runs on a webrtcbin thread
  // while the viewer goes still reads valid memory.
  return g_signal_connect_data(
      instance, signal, callback, new Handle(alive_),
      [](gpointer handle, GClosure*) { delete static_cast<Handle*>(handle); }, GConnectFlags(0));
}

WebRtcViewer::WebRtcViewer(CameraEncoder& encoder, const ViewerOffer& offer,
                           const IceServers& servers, Events events)
    : encoder_(encoder), events_(std::move(events)) {
  queue_ = make("queue");
  // A viewer that cannot keep up loses frames here, never holds the others.
  g_object_set(queue_, "leaky", 2, "max-size-buffers", 8u, "max-size-bytes", 0u, "max-size-time",
               guint64(0), nullptr);
  bool h264 = encoder.video() == WebRtcVideo::kH264;
  int payload = h264 ? offer.h264Payload : offer.vp8Payload;
  if (h264) h264Payload_ = offer.h264Payload, h264Format_ = offer.h264Format;
  if (h264) {
    // SPS and PPS before every key frame: a viewer may join at any one.
    payloader_ = make("rtph264pay");
    g_object_set(payloader_, "config-interval", -1, nullptr);
    gst_util_set_object_arg(G_OBJECT(payloader_), "aggregate-mode", "zero-latency");
  } else {
    // 15-bit picture ids, as browsers send them.
    payloader_ = make("rtpvp8pay");
    gst_util_set_object_arg(G_OBJECT(payloader_), "picture-id-mode", "15-bit");
  }
  // The payload type the viewer's offer gave the codec.
  g_object_set(payloader_, "pt", guint(payload), "mtu", 1200u, nullptr);
  webrtc_ = make("webrtcbin");
  gst_util_set_object_arg(G_OBJECT(webrtc_), "bundle-policy", "max-bundle");
  if (!servers.stun.empty()) g_object_set(webrtc_, "stun-server", servers.stun.c_str(), nullptr);
  if (!servers.turn.empty()) g_object_set(webrtc_, "turn-server", servers.turn.c_str(), nullptr);
  GstWebRTCICE* ice = nullptr;
  g_object_get(webrtc_, "ice-agent", &ice, nullptr);
  for (const auto& address : servers.localAddresses) {
    gboolean added = FALSE;
    g_signal_emit_by_name(ice, "add-local-ip-address", address.c_str(), &added);
  }
  withoutUpnp(ice);
  gst_object_unref(ice);
  gst_bin_add_many(encoder_.pipeline(), queue_, payloader_, webrtc_, nullptr);
  gst_element_link(queue_, payloader_);

  // The answer names exactly the codec and payload type that will flow, as
  // the offer wrote them (for H.264 its profile-level-id and
  // packetization-mode): webrtcbin would otherwise answer with the first
  // payload type of the codec's name, or with what has flowed so far (for
  // the first viewer, nothing: an inactive VP8 line).
  GstCaps* caps = offeredCaps(offer, payload);
  if (!caps)
    caps = gst_caps_new_simple("application/x-rtp", "media", G_TYPE_STRING, "video",
                               "encoding-name", G_TYPE_STRING, h264 ? "H264" : "VP8", "payload",
                               G_TYPE_INT, payload, "clock-rate", G_TYPE_INT, 90000, nullptr);
  GstPadTemplate* sinks =
      gst_element_class_get_pad_template(GST_ELEMENT_GET_CLASS(webrtc_), "sink_%u");
  GstPad* sink = gst_element_request_pad(webrtc_, sinks, nullptr, caps);
  GstWebRTCRTPTransceiver* transceiver = nullptr;
  g_object_get(sink, "transceiver", &transceiver, nullptr);
  if (transceiver) {
    g_object_set(transceiver, "direction", GST_WEBRTC_RTP_TRANSCEIVER_DIRECTION_SENDONLY,
                 "codec-preferences", caps, nullptr);
    gst_object_unref(transceiver);
  }
  gst_caps_unref(caps);
  GstPad* payloaded = gst_element_get_static_pad(payloader_, "src");
  gst_pad_link(payloaded, sink);
  gst_object_unref(payloaded);
  gst_object_unref(sink);

  handlers_ = {
      connect(webrtc_, "on-ice-candidate", G_CALLBACK(onIceCandidate)),
      connect(webrtc_, "notify::ice-gathering-state", G_CALLBACK(onGatheringState)),
      connect(webrtc_, "notify::connection-state", G_CALLBACK(onConnectionState)),
      connect(webrtc_, "on-data-channel", G_CALLBACK(onDataChannel)),
  };
  if ((rtpbin_ = gst_bin_get_by_name(GST_BIN(webrtc_), "rtpbin")))
    heardHandler_ = g_signal_connect_data(
        rtpbin_, "on-ssrc-active", G_CALLBACK(+[](GstElement*, guint, guint, gpointer heard) {
          static_cast<std::shared_ptr<std::atomic<int64_t>>*>(heard)->get()->store(
              std::chrono::steady_clock::now().time_since_epoch().count());
        }),
        new std::shared_ptr<std::atomic<int64_t>>(heard_),
        [](gpointer heard, GClosure*) {
          delete static_cast<std::shared_ptr<std::atomic<int64_t>>*>(heard);
        },
        GConnectFlags(0));
  if (h264) startOnAnIdrOnceConnected();
  gst_element_sync_state_with_parent(webrtc_);
  gst_element_sync_state_with_parent(payloader_);
  gst_element_sync_state_with_parent(queue_);
  teePad_ = gst_element_request_pad_simple(encoder_.tee(), "src_%u");
  GstPad* queued = gst_element_get_static_pad(queue_, "sink");
  gst_pad_link(teePad_, queued);
  gst_object_unref(queued);
  // A branch added to a running pipeline has no latency configured until
  // the pipeline works it out again (webrtcbin's RTP session needs it to
  // time its packets).
  gst_bin_recalculate_latency(encoder_.pipeline());
  negotiate(offer.sdp);
}

void WebRtcViewer::startOnAnIdrOnceConnected() {
  // Read on the queue's streaming thread, written on webrtcbin's: neither
  // may touch the viewer, which lives on the main loop.
  using Flag = std::shared_ptr<std::atomic<bool>>;
  auto connected = std::make_shared<std::atomic<bool>>(false);
  handlers_.push_back(g_signal_connect_data(
      webrtc_, "notify::connection-state",
      G_CALLBACK(+[](GstElement* webrtc, GParamSpec*, gpointer flag) {
        GstWebRTCPeerConnectionState state;
        g_object_get(webrtc, "connection-state", &state, nullptr);
        static_cast<Flag*>(flag)->get()->store(state == GST_WEBRTC_PEER_CONNECTION_STATE_CONNECTED);
      }),
      new Flag(connected), [](gpointer flag, GClosure*) { delete static_cast<Flag*>(flag); },
      GConnectFlags(0)));
  // Until the connection is up webrtcbin sends nothing, and what it was
  // given is lost: the first frame to go is the first IDR after. An
  // I-frame that is no IDR (an encoder's scene cut; h264parse flags it a
  // key frame too) is no place to start, so it is decided from the
  // bitstream. The payloader puts the SPS and PPS before it.
  GstPad* queued = gst_element_get_static_pad(queue_, "src");
  gst_pad_add_probe(
      queued, GST_PAD_PROBE_TYPE_BUFFER,
      [](GstPad* pad, GstPadProbeInfo* info, gpointer flag) {
        if (!static_cast<Flag*>(flag)->get()->load()) return GST_PAD_PROBE_DROP;
        GstCaps* caps = gst_pad_get_current_caps(pad);
        bool starts = gst::h264StartsDecoding(GST_PAD_PROBE_INFO_BUFFER(info), caps);
        if (caps) gst_caps_unref(caps);
        return starts ? GST_PAD_PROBE_REMOVE : GST_PAD_PROBE_DROP;
      },
      new Flag(connected), [](gpointer flag) { delete static_cast<Flag*>(flag); });
  gst_object_unref(queued);
}

void WebRtcViewer::negotiate(const std::string& offer) {
  GstSDPMessage* sdp = nullptr;
  gst_sdp_message_new_from_text(offer.c_str(), &sdp);  // read before: it parses
  GstWebRTCSessionDescription* description =
      gst_webrtc_session_description_new(GST_WEBRTC_SDP_TYPE_OFFER, sdp);
  // webrtcbin runs its operations in order: the answer is made after the
  // offer was taken (or says why the offer was not).
  g_signal_emit_by_name(webrtc_, "set-remote-description", description, nullptr);
  gst_webrtc_session_description_free(description);
  GstPromise* answered = gst_promise_new_with_change_func(
      onAnswerCreated, new Answering{alive_, GST_ELEMENT(gst_object_ref(webrtc_))},
      [](gpointer data) {
        auto* answering = static_cast<Answering*>(data);
        gst_object_unref(answering->webrtc);
        delete answering;
      });
  g_signal_emit_by_name(webrtc_, "create-answer", nullptr, answered);
  gst_promise_unref(answered);
}

void WebRtcViewer::waitForCandidates(const std::string& answer) {
  answer_ = answer;
  gathering_.answerMade(AnswerGathering::Clock::now());
  // At the patience's end the answer goes with the candidates it has.
  gatherTimer_ = g_timeout_add(
      std::chrono::duration_cast<std::chrono::milliseconds>(kGatheringPatience).count(),
      [](gpointer self) -> gboolean {
        auto* viewer = static_cast<WebRtcViewer*>(self);
        viewer->gatherTimer_ = 0;
        // The time it stands for: a timer is not early by GLib's clock.
        viewer->answerIfGathered(*viewer->gathering_.patienceEnds());
        return G_SOURCE_REMOVE;
      },
      this);
  answerIfGathered(AnswerGathering::Clock::now());
}

void WebRtcViewer::onAnswerCreated(GstPromise* promise, gpointer data) {
  // On webrtcbin's thread: the viewer may be going on the main loop, so
  // only the element's own reference is used here.
  auto* answering = static_cast<Answering*>(data);
  std::string answer, error;
  if (gst_promise_wait(promise) != GST_PROMISE_RESULT_REPLIED) {
    error = "webrtcbin made no answer";
  } else if (const GstStructure* reply = gst_promise_get_reply(promise)) {
    GError* failure = nullptr;
    GstWebRTCSessionDescription* description = nullptr;
    if (gst_structure_get(reply, "error", G_TYPE_ERROR, &failure, nullptr)) {
      error = failure->message;
      g_error_free(failure);
    } else if (gst_structure_get(reply, "answer", GST_TYPE_WEBRTC_SESSION_DESCRIPTION, &description,
                                 nullptr)) {
      gchar* text = gst_sdp_message_as_text(description->sdp);
      answer = text;
      g_free(text);
      g_signal_emit_by_name(answering->webrtc, "set-local-description", description, nullptr);
      gst_webrtc_session_description_free(description);
    } else {
      error = "webrtcbin's reply held no answer";
    }
  }
  handOver(&answering->handle, [answer, error](WebRtcViewer& self) {
    if (!error.empty()) return self.finish(unexpected("the offer cannot be answered: " + error));
    self.waitForCandidates(answer);
  });
}

void WebRtcViewer::onIceCandidate(GstElement*, guint mline, gchar* candidate, gpointer handle) {
  handOver(handle, [mline, text = std::string(candidate)](WebRtcViewer& self) {
    self.candidates_.emplace_back(mline, text);
    self.gathering_.candidateFound();
    self.answerIfGathered(AnswerGathering::Clock::now());
  });
}

void WebRtcViewer::onGatheringState(GstElement* webrtc, GParamSpec*, gpointer handle) {
  GstWebRTCICEGatheringState state;
  g_object_get(webrtc, "ice-gathering-state", &state, nullptr);
  if (state != GST_WEBRTC_ICE_GATHERING_STATE_COMPLETE) return;
  handOver(handle, [](WebRtcViewer& self) {
    self.gathering_.gatheringComplete();
    self.answerIfGathered(AnswerGathering::Clock::now());
  });
}

void WebRtcViewer::answerIfGathered(AnswerGathering::Clock::time_point now) {
  if (answered_ || !gathering_.ready(now)) return;
  finish(
      answerWithH264Format(answerWithCandidates(answer_, candidates_), h264Payload_, h264Format_));
}

void WebRtcViewer::finish(Expected<std::string, std::string> answer) {
  if (answered_) return;
  answered_ = true;
  if (gatherTimer_) g_source_remove(gatherTimer_);
  gatherTimer_ = 0;
  events_.answered(std::move(answer));
}

void WebRtcViewer::onConnectionState(GstElement* webrtc, GParamSpec*, gpointer handle) {
  GstWebRTCPeerConnectionState state;
  g_object_get(webrtc, "connection-state", &state, nullptr);
  handOver(handle, [state](WebRtcViewer& self) {
    self.connectionState_ = state;
    if (state == GST_WEBRTC_PEER_CONNECTION_STATE_FAILED ||
        state == GST_WEBRTC_PEER_CONNECTION_STATE_CLOSED)
      self.events_.ended();
  });
}

std::chrono::steady_clock::time_point WebRtcViewer::lastHeard() const {
  return std::chrono::steady_clock::time_point(std::chrono::steady_clock::duration(heard_->load()));
}

void WebRtcViewer::onDataChannel(GstElement*, GstWebRTCDataChannel* channel, gpointer handle) {
  gchar* label = nullptr;
  g_object_get(channel, "label", &label, nullptr);
  bool drive = g_strcmp0(label, "drive") == 0;
  g_free(label);
  if (!drive) return gst_webrtc_data_channel_close(channel);
  gst_object_ref(channel);
  handOver(handle, [channel](WebRtcViewer& self) {
    self.openDriveChannel(channel);
    gst_object_unref(channel);
  });
}

void WebRtcViewer::openDriveChannel(GstWebRTCDataChannel* channel) {
  if (drive_) {  // one per viewer: a second is closed
    gst_webrtc_data_channel_close(channel);
    return;
  }
  drive_ = GST_WEBRTC_DATA_CHANNEL(gst_object_ref(channel));
  auto onText = +[](GstWebRTCDataChannel*, gchar* text, gpointer handle) {
    handOver(handle, [text = std::string(text ? text : "")](WebRtcViewer& self) {
      std::string reply = self.events_.driveMessage(text);
      if (!reply.empty() && self.drive_)
        gst_webrtc_data_channel_send_string(self.drive_, reply.c_str());
    });
  };
  auto onBytes = +[](GstWebRTCDataChannel*, GBytes*, gpointer handle) {
    handOver(handle, [](WebRtcViewer& self) {
      std::string reply = self.events_.driveMessage(std::nullopt);
      if (!reply.empty() && self.drive_)
        gst_webrtc_data_channel_send_string(self.drive_, reply.c_str());
    });
  };
  auto onClose = +[](GstWebRTCDataChannel*, gpointer handle) {
    handOver(handle, [](WebRtcViewer& self) {
      if (!self.drive_) return;
      for (gulong handler : self.driveHandlers_) g_signal_handler_disconnect(self.drive_, handler);
      self.driveHandlers_.clear();
      gst_clear_object(&self.drive_);
      self.events_.driveClosed();
    });
  };
  driveHandlers_ = {connect(drive_, "on-message-string", G_CALLBACK(onText)),
                    connect(drive_, "on-message-data", G_CALLBACK(onBytes)),
                    connect(drive_, "on-close", G_CALLBACK(onClose))};
}

WebRtcViewer::~WebRtcViewer() {
  alive_.reset();  // nothing handed over runs from here on
  if (gatherTimer_) g_source_remove(gatherTimer_);
  for (gulong handler : handlers_) g_signal_handler_disconnect(webrtc_, handler);
  if (rtpbin_) {
    g_signal_handler_disconnect(rtpbin_, heardHandler_);
    gst_object_unref(rtpbin_);
  }
  if (drive_) {
    for (gulong handler : driveHandlers_) g_signal_handler_disconnect(drive_, handler);
    events_.driveClosed();
    gst_object_unref(drive_);
  }
  // Off the tee first, so no frame goes towards elements that are stopping.
  GstPad* queued = gst_element_get_static_pad(queue_, "sink");
  gst_pad_unlink(teePad_, queued);
  gst_object_unref(queued);
  gst_element_release_request_pad(encoder_.tee(), teePad_);
  gst_object_unref(teePad_);
  for (GstElement* element : {webrtc_, payloader_, queue_}) {
    gst_object_ref(element);
    gst_bin_remove(encoder_.pipeline(), element);
    gst_element_set_state(element, GST_STATE_NULL);
    gst_object_unref(element);
  }
  encoder_.releaseMessages();
}

}  // namespace wircam::recorder
