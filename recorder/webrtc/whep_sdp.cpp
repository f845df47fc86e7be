#include "webrtc/whep_sdp.h"

#include <glib.h>

#include <memory>
#include <sstream>
#include <string_view>
#include <vector>

namespace wircam::recorder {

namespace {

struct SdpDeleter {
  void operator()(GstSDPMessage* message) const { gst_sdp_message_free(message); }
};
using SdpMessage = std::unique_ptr<GstSDPMessage, SdpDeleter>;

// GStreamer's parser takes almost anything: a version and an m-line show
// it is an SDP at all.
SdpMessage parse(const std::string& text) {
  GstSDPMessage* message = nullptr;
  if (text.empty() || gst_sdp_message_new_from_text(text.c_str(), &message) != GST_SDP_OK)
    return nullptr;
  SdpMessage parsed(message);
  if (!gst_sdp_message_get_version(message) || gst_sdp_message_medias_len(message) == 0)
    return nullptr;
  return parsed;
}

std::string asText(const GstSDPMessage* message) {
  gchar* text = gst_sdp_message_as_text(message);
  std::string result = text ? text : "";
  g_free(text);
  return result;
}

bool hasAttribute(const GstSDPMedia* media, const char* key) {
  return gst_sdp_media_get_attribute_val(media, key) != nullptr;
}

// The payload types of "<pt> NAME/90000" among the m-line's rtpmaps.
std::vector<int> payloadsOf(const GstSDPMedia* media, const char* name) {
  std::vector<int> payloads;
  for (guint i = 0;; ++i) {
    const char* rtpmap = gst_sdp_media_get_attribute_val_n(media, "rtpmap", i);
    if (!rtpmap) return payloads;
    int payload = -1;
    char encoding[32] = {};
    if (sscanf(rtpmap, "%d %31[^/]/90000", &payload, encoding) == 2 &&
        g_ascii_strcasecmp(encoding, name) == 0 && payload >= 0 && payload < 128)
      payloads.push_back(payload);
  }
}

// The format parameters of `payload` ("a=fmtp:96 a=1;b=2"), or "".
std::string formatOf(const GstSDPMedia* media, int payload) {
  std::string prefix = std::to_string(payload) + " ";
  for (guint i = 0;; ++i) {
    const char* fmtp = gst_sdp_media_get_attribute_val_n(media, "fmtp", i);
    if (!fmtp) return "";
    if (std::string_view(fmtp).starts_with(prefix)) return fmtp + prefix.size();
  }
}

// The H.264 payload type for Main profile (profile_idc 0x4d) in
// packetization mode 1 that takes the recording's stream: one that allows
// any level (level-asymmetry-allowed=1) first, else the highest level
// offered. -1 when none is Main: its profile must match exactly, and a
// Constrained Baseline (42e0…) payload type would carry nothing.
int h264MainPayloadOf(const GstSDPMedia* media) {
  int best = -1, bestScore = -1;
  for (int payload : payloadsOf(media, "H264")) {
    std::string format = formatOf(media, payload);
    auto profile = format.find("profile-level-id=");
    if (format.find("packetization-mode=1") == std::string::npos || profile == std::string::npos ||
        format.size() < profile + 17 + 6 ||
        g_ascii_strncasecmp(format.c_str() + profile + 17, "4d", 2) != 0)
      continue;
    int level =
        static_cast<int>(g_ascii_strtoll(format.substr(profile + 17 + 4, 2).c_str(), nullptr, 16));
    int score = (format.find("level-asymmetry-allowed=1") != std::string::npos ? 256 : 0) + level;
    if (score > bestScore) best = payload, bestScore = score;
  }
  return best;
}

// "candidate:F C PROTO PRIO ADDRESS PORT typ T ...": the address.
std::string candidateAddress(const char* value) {
  std::istringstream words(value ? value : "");
  std::string word;
  for (int i = 0; i < 5 && words >> word; ++i) {
  }
  return word;
}

}  // namespace

Expected<ViewerOffer, std::string> readViewerOffer(std::string_view body,
                                                   const std::set<std::string>& allowedHosts) {
  if (body.size() > kMaxOfferBytes)
    return unexpected("the offer is " + std::to_string(body.size()) + " bytes; at most " +
                      std::to_string(kMaxOfferBytes));
  if (body.find('\0') != std::string_view::npos) return unexpected("the offer is not SDP text");
  auto message = parse(std::string(body));
  if (!message) return unexpected("the offer is not SDP (v=, o=, s=, t=, m= lines)");
  unsigned medias = gst_sdp_message_medias_len(message.get());
  if (medias > kMaxOfferMedia)
    return unexpected("the offer has " + std::to_string(medias) + " m-lines; at most " +
                      std::to_string(kMaxOfferMedia));
  ViewerOffer offer;
  bool video = false;
  for (unsigned m = 0; m < medias; ++m) {
    auto* media = const_cast<GstSDPMedia*>(gst_sdp_message_get_media(message.get(), m));
    std::string kind = gst_sdp_media_get_media(media) ? gst_sdp_media_get_media(media) : "";
    if (kind == "application") offer.dataChannel = true;
    if (kind == "video" && !video && !hasAttribute(media, "sendonly") &&
        !hasAttribute(media, "inactive") && gst_sdp_media_get_port(media) != 0) {
      video = true;
      offer.videoMedia = m;
      auto vp8 = payloadsOf(media, "VP8");
      offer.vp8Payload = vp8.empty() ? -1 : vp8.front();
      offer.h264Payload = h264MainPayloadOf(media);
      if (offer.h264Payload >= 0) offer.h264Format = formatOf(media, offer.h264Payload);
    }
    for (guint a = gst_sdp_media_attributes_len(media); a-- > 0;) {
      const GstSDPAttribute* attribute = gst_sdp_media_get_attribute(media, a);
      if (g_strcmp0(attribute->key, "candidate") != 0) continue;
      if (allowedHosts.count(candidateAddress(attribute->value))) continue;
      gst_sdp_media_remove_attribute(media, a);
      ++offer.droppedCandidates;
    }
  }
  if (!video) return unexpected("the offer has no video m-line that receives (recvonly)");
  if (offer.vp8Payload < 0 && offer.h264Payload < 0)
    return unexpected("the offer's video takes neither VP8 nor H.264 Main (packetization-mode=1)");
  offer.sdp = asText(message.get());
  return offer;
}

std::string answerWithH264Format(const std::string& answer, int payload,
                                 const std::string& format) {
  auto message = parse(answer);
  if (!message || payload < 0 || format.empty()) return answer;
  bool mended = false;
  for (unsigned m = 0; m < gst_sdp_message_medias_len(message.get()); ++m) {
    auto* media = const_cast<GstSDPMedia*>(gst_sdp_message_get_media(message.get(), m));
    if (payloadsOf(media, "H264") != std::vector<int>{payload}) continue;
    if (formatOf(media, payload).find("profile-level-id=") != std::string::npos) continue;
    std::string prefix = std::to_string(payload) + " ";
    for (guint i = gst_sdp_media_attributes_len(media); i-- > 0;) {
      const GstSDPAttribute* attribute = gst_sdp_media_get_attribute(media, i);
      if (g_strcmp0(attribute->key, "fmtp") == 0 && attribute->value &&
          std::string_view(attribute->value).starts_with(prefix))
        gst_sdp_media_remove_attribute(media, i);
    }
    gst_sdp_media_add_attribute(media, "fmtp", (prefix + format).c_str());
    mended = true;
  }
  return mended ? asText(message.get()) : answer;
}

std::string answerWithCandidates(const std::string& answer,
                                 const std::vector<LocalCandidate>& candidates) {
  auto message = parse(answer);
  if (!message) return answer;
  unsigned medias = gst_sdp_message_medias_len(message.get());
  for (const auto& [index, text] : candidates) {
    if (index >= medias) continue;
    std::string value = text.starts_with("candidate:") ? text.substr(10) : text;
    auto* media = const_cast<GstSDPMedia*>(gst_sdp_message_get_media(message.get(), index));
    // webrtcbin may have put it in its description already.
    bool present = false;
    for (guint i = 0; const char* known = gst_sdp_media_get_attribute_val_n(media, "candidate", i);
         ++i)
      present = present || value == known;
    if (!present) gst_sdp_media_add_attribute(media, "candidate", value.c_str());
  }
  for (unsigned m = 0; m < medias; ++m) {
    auto* media = const_cast<GstSDPMedia*>(gst_sdp_message_get_media(message.get(), m));
    if (!hasAttribute(media, "end-of-candidates"))
      gst_sdp_media_add_attribute(media, "end-of-candidates", "");
  }
  return asText(message.get());
}

}  // namespace wircam::recorder
