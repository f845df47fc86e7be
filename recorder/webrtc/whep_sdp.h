// The SDP of a WHEP exchange, checked and mended apart from any pipeline:
// a viewer's offer is read with GStreamer's SDP parser and bounded, the
// ICE candidates it names for hosts other than the viewer's own are taken
// out (so the recorder never sends connectivity checks where a page points
// it), and the answer gets the candidates the recorder gathered, as WHEP
// without trickle ICE wants.
#pragma once

#include <gst/sdp/sdp.h>

#include <set>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "common/expected.h"

namespace wircam::recorder {

// An offer is a few kilobytes; anything near this is hostile.
constexpr size_t kMaxOfferBytes = 16 * 1024;
// audio, video, data: a page offers at most these few.
constexpr unsigned kMaxOfferMedia = 8;

struct ViewerOffer {
  std::string sdp;          // as it goes to webrtcbin: only the allowed candidates
  unsigned videoMedia = 0;  // index of the video m-line that receives
  int vp8Payload = -1;      // its payload type for VP8/90000, or -1
  // For H.264 Main (profile-level-id 4d…) in packetization mode 1, as an
  // H.264 recording is encoded, or -1.
  int h264Payload = -1;
  std::string h264Format;  // its format parameters, as offered
  bool dataChannel = false;
  unsigned droppedCandidates = 0;  // for another host, or a name
};

// The offer, or why it cannot be answered: too big, not SDP, no video the
// viewer receives, neither VP8 nor H.264 Main. Candidates are kept only when their address is
// one of `allowedHosts` (IP addresses as text: the viewer's own, and a
// TURN server's).
Expected<ViewerOffer, std::string> readViewerOffer(std::string_view body,
                                                   const std::set<std::string>& allowedHosts);

// A candidate webrtcbin gathered: the m-line it belongs to and its text
// ("candidate:1 1 UDP 2015363327 10.0.0.2 41230 typ host").
using LocalCandidate = std::pair<unsigned, std::string>;

// `answer` naming the profile the viewer offered for H.264 `payload`
// (`format`, its a=fmtp) where webrtcbin left it out (it writes what has
// flowed, and before the first frame nothing): without profile-level-id a
// viewer must take it for Baseline. `answer` unchanged otherwise.
std::string answerWithH264Format(const std::string& answer, int payload, const std::string& format);

// `answer` with each candidate added to its m-line and end-of-candidates
// on every m-line; `answer` unchanged if it does not parse.
std::string answerWithCandidates(const std::string& answer,
                                 const std::vector<LocalCandidate>& candidates);

}  // namespace wircam::recorder
