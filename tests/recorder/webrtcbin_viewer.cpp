#include "webrtcbin_viewer.h"

#include <gst/sdp/sdp.h>
#define GST_USE_UNSTABLE_API
#include <gst/webrtc/webrtc.h>

#include "wait_for.h"

namespace wircam::testing {

WebRtcBinViewer::WebRtcBinViewer(const char* codecs) {
  pipeline_ = gst_pipeline_new(nullptr);
  webrtc_ = gst_element_factory_make("webrtcbin", nullptr);
  gst_util_set_object_arg(G_OBJECT(webrtc_), "bundle-policy", "max-bundle");
  gst_bin_add(GST_BIN(pipeline_), webrtc_);
  // Its host candidate on loopback, where the recorder listens.
  GstWebRTCICE* ice = nullptr;
  g_object_get(webrtc_, "ice-agent", &ice, nullptr);
  gboolean added = FALSE;
  g_signal_emit_by_name(ice, "add-local-ip-address", "127.0.0.1", &added);
  gst_object_unref(ice);
  GstCaps* offered = gst_caps_from_string(codecs);
  GstWebRTCRTPTransceiver* transceiver = nullptr;
  g_signal_emit_by_name(webrtc_, "add-transceiver", GST_WEBRTC_RTP_TRANSCEIVER_DIRECTION_RECVONLY,
                        offered, &transceiver);
  gst_caps_unref(offered);
  if (transceiver) gst_object_unref(transceiver);
  g_signal_connect(webrtc_, "pad-added", G_CALLBACK(onPad), this);
  gst_element_set_state(pipeline_, GST_STATE_PLAYING);
}

WebRtcBinViewer::~WebRtcBinViewer() {
  gst_element_set_state(pipeline_, GST_STATE_NULL);
  gst_object_unref(pipeline_);
}

std::string WebRtcBinViewer::offer() {
  GstPromise* promise = gst_promise_new();
  g_signal_emit_by_name(webrtc_, "create-offer", nullptr, promise);
  gst_promise_wait(promise);
  GstWebRTCSessionDescription* offer = nullptr;
  gst_structure_get(gst_promise_get_reply(promise), "offer", GST_TYPE_WEBRTC_SESSION_DESCRIPTION,
                    &offer, nullptr);
  gst_promise_unref(promise);
  g_signal_emit_by_name(webrtc_, "set-local-description", offer, nullptr);
  gst_webrtc_session_description_free(offer);
  waitFor([this] {
    GstWebRTCICEGatheringState state;
    g_object_get(webrtc_, "ice-gathering-state", &state, nullptr);
    return state == GST_WEBRTC_ICE_GATHERING_STATE_COMPLETE;
  });
  GstWebRTCSessionDescription* local = nullptr;
  g_object_get(webrtc_, "local-description", &local, nullptr);
  gchar* text = gst_sdp_message_as_text(local->sdp);
  std::string sdp = text;
  g_free(text);
  gst_webrtc_session_description_free(local);
  return sdp;
}

void WebRtcBinViewer::answer(const std::string& sdp) {
  GstSDPMessage* message = nullptr;
  gst_sdp_message_new_from_text(sdp.c_str(), &message);
  GstWebRTCSessionDescription* answer =
      gst_webrtc_session_description_new(GST_WEBRTC_SDP_TYPE_ANSWER, message);
  g_signal_emit_by_name(webrtc_, "set-remote-description", answer, nullptr);
  gst_webrtc_session_description_free(answer);
}

std::string WebRtcBinViewer::firstAccessUnit() const {
  MutexLock lock(mutex_);
  return firstAccessUnit_;
}

void WebRtcBinViewer::onPad(GstElement*, GstPad* pad, WebRtcBinViewer* self) {
  if (GST_PAD_DIRECTION(pad) != GST_PAD_SRC) return;
  GstElement* decode = gst_parse_bin_from_description(
      "rtph264depay name=depay ! video/x-h264,stream-format=byte-stream,alignment=au "
      "! h264parse ! avdec_h264 ! fakesink name=frames signal-handoffs=true sync=false",
      TRUE, nullptr);
  GstElement* frames = gst_bin_get_by_name(GST_BIN(decode), "frames");
  g_signal_connect(frames, "handoff",
                   G_CALLBACK(+[](GstElement*, GstBuffer*, GstPad*, WebRtcBinViewer* viewer) {
                     ++viewer->decoded_;
                   }),
                   self);
  gst_object_unref(frames);
  GstElement* depay = gst_bin_get_by_name(GST_BIN(decode), "depay");
  GstPad* depayloaded = gst_element_get_static_pad(depay, "src");
  gst_pad_add_probe(
      depayloaded, GST_PAD_PROBE_TYPE_BUFFER,
      [](GstPad*, GstPadProbeInfo* info, gpointer data) {
        auto* viewer = static_cast<WebRtcBinViewer*>(data);
        GstMapInfo map;
        GstBuffer* buffer = GST_PAD_PROBE_INFO_BUFFER(info);
        if (gst_buffer_map(buffer, &map, GST_MAP_READ)) {
          MutexLock lock(viewer->mutex_);
          viewer->firstAccessUnit_.assign(reinterpret_cast<const char*>(map.data), map.size);
          gst_buffer_unmap(buffer, &map);
        }
        return GST_PAD_PROBE_REMOVE;
      },
      self, nullptr);
  gst_object_unref(depayloaded);
  gst_object_unref(depay);
  gst_bin_add(GST_BIN(self->pipeline_), decode);
  gst_element_sync_state_with_parent(decode);
  GstPad* sink = gst_element_get_static_pad(decode, "sink");
  gst_pad_link(pad, sink);
  gst_object_unref(sink);
}

}  // namespace wircam::testing
