// A viewer's WHEP offer read and bounded, its candidates for other hosts
// left out, and the answer given the recorder's candidates.
#include "webrtc/whep_sdp.h"

#include <gtest/gtest.h>

namespace wircam::recorder {
namespace {

// What Chromium offers for a receive-only video and a data channel, cut
// down: VP9 first, VP8 at 96, one mDNS host candidate and two IPs.
const std::string kOffer =
    "v=0\r\no=- 42 2 IN IP4 127.0.0.1\r\ns=-\r\nt=0 0\r\na=group:BUNDLE 0 1\r\n"
    "m=video 9 UDP/TLS/RTP/SAVPF 98 96 97\r\nc=IN IP4 0.0.0.0\r\n"
    "a=candidate:1 1 udp 2113937151 5d2f0f2c-1d4b-4d7f-9c7e-0d6f7b9a1c2e.local 45698 typ host\r\n"
    "a=candidate:2 1 udp 2113937151 127.0.0.1 45699 typ host\r\n"
    "a=candidate:3 1 udp 2113937151 192.0.2.77 45700 typ host\r\n"
    "a=ice-ufrag:BMgz\r\na=ice-pwd:+VxwY9p7YVQQRFGi1gqpXvIm\r\na=setup:actpass\r\na=mid:0\r\n"
    "a=recvonly\r\na=rtcp-mux\r\na=rtpmap:98 VP9/90000\r\na=rtpmap:96 VP8/90000\r\n"
    "a=rtpmap:97 rtx/90000\r\na=fmtp:97 apt=96\r\n"
    "m=application 9 UDP/DTLS/SCTP webrtc-datachannel\r\nc=IN IP4 0.0.0.0\r\na=mid:1\r\n"
    "a=sctp-port:5000\r\n";

TEST(WhepSdp, AnOfferKeepsOnlyTheViewersOwnCandidates) {
  auto offer = readViewerOffer(kOffer, {"127.0.0.1"});
  ASSERT_TRUE(offer) << offer.error();
  EXPECT_EQ(offer->videoMedia, 0u);
  EXPECT_EQ(offer->vp8Payload, 96);
  EXPECT_EQ(offer->h264Payload, -1);
  EXPECT_TRUE(offer->dataChannel);
  EXPECT_EQ(offer->droppedCandidates, 2u);  // the name and the other host
  EXPECT_NE(offer->sdp.find("127.0.0.1 45699"), std::string::npos) << offer->sdp;
  EXPECT_EQ(offer->sdp.find(".local"), std::string::npos) << offer->sdp;
  EXPECT_EQ(offer->sdp.find("192.0.2.77"), std::string::npos) << offer->sdp;
  // A TURN server's address is allowed too.
  auto withTurn = readViewerOffer(kOffer, {"127.0.0.1", "192.0.2.77"});
  ASSERT_TRUE(withTurn);
  EXPECT_EQ(withTurn->droppedCandidates, 1u);
}

TEST(WhepSdp, H264IsTakenInMainProfileAndPacketizationModeOne) {
  std::string offered = kOffer;
  offered.replace(offered.find("a=rtpmap:97 rtx/90000"), 0,
                  "a=rtpmap:102 H264/90000\r\n"
                  "a=fmtp:102 level-asymmetry-allowed=1;packetization-mode=1;"
                  "profile-level-id=42e01f\r\n"
                  "a=rtpmap:39 H264/90000\r\n"
                  "a=fmtp:39 level-asymmetry-allowed=1;packetization-mode=0;"
                  "profile-level-id=4d001f\r\n"
                  "a=rtpmap:116 H264/90000\r\n"
                  "a=fmtp:116 level-asymmetry-allowed=1;packetization-mode=1;"
                  "profile-level-id=4d001f\r\n");
  auto offer = readViewerOffer(offered, {"127.0.0.1"});
  ASSERT_TRUE(offer) << offer.error();
  EXPECT_EQ(offer->h264Payload, 116);  // not baseline (102), not mode 0 (39)
  // Without VP8, H.264 alone will do.
  std::string onlyH264 = offered;
  onlyH264.replace(onlyH264.find("VP8"), 3, "XYZ");
  auto h264 = readViewerOffer(onlyH264, {"127.0.0.1"});
  ASSERT_TRUE(h264) << h264.error();
  EXPECT_EQ(h264->vp8Payload, -1);
  EXPECT_EQ(h264->h264Payload, 116);
}

TEST(WhepSdp, WhatCannotBeAnsweredIsRefusedWithTheReason) {
  auto refused = [](const std::string& body) {
    auto offer = readViewerOffer(body, {"127.0.0.1"});
    return offer ? std::string("accepted") : offer.error();
  };
  EXPECT_EQ(refused(""), "the offer is not SDP (v=, o=, s=, t=, m= lines)");
  EXPECT_EQ(refused("hello"), "the offer is not SDP (v=, o=, s=, t=, m= lines)");
  EXPECT_EQ(refused(std::string("v=0\r\n\0m=video", 13)), "the offer is not SDP text");
  EXPECT_EQ(refused(std::string(kMaxOfferBytes + 1, 'a')),
            "the offer is " + std::to_string(kMaxOfferBytes + 1) + " bytes; at most " +
                std::to_string(kMaxOfferBytes));
  std::string noVp8 = kOffer;
  noVp8.replace(noVp8.find("VP8"), 3, "XYZ");
  EXPECT_EQ(refused(noVp8),
            "the offer's video takes neither VP8 nor H.264 Main (packetization-mode=1)");
  std::string sending = kOffer;
  sending.replace(sending.find("recvonly"), 8, "sendonly");
  EXPECT_EQ(refused(sending), "the offer has no video m-line that receives (recvonly)");
  std::string many = "v=0\r\no=- 1 1 IN IP4 0.0.0.0\r\ns=-\r\nt=0 0\r\n";
  for (int i = 0; i < 9; ++i) many += "m=audio 9 RTP/AVP 0\r\n";
  EXPECT_EQ(refused(many), "the offer has 9 m-lines; at most 8");
}

TEST(WhepSdp, TheAnswerCarriesEachCandidateOnceAndTheirEnd) {
  std::string answer =
      "v=0\r\no=- 1 2 IN IP4 0.0.0.0\r\ns=-\r\nt=0 0\r\nm=video 9 UDP/TLS/RTP/SAVPF 96\r\n"
      "c=IN IP4 0.0.0.0\r\na=mid:0\r\na=candidate:1 1 UDP 2015363327 10.0.0.2 41230 typ host\r\n"
      "m=application 9 UDP/DTLS/SCTP webrtc-datachannel\r\nc=IN IP4 0.0.0.0\r\na=mid:1\r\n";
  auto mended =
      answerWithCandidates(answer, {{0, "candidate:1 1 UDP 2015363327 10.0.0.2 41230 typ host"},
                                    {0, "candidate:2 1 UDP 2015363583 10.0.0.3 41231 typ host"},
                                    {7, "candidate:3 1 UDP 2015363583 10.0.0.4 41232 typ host"}});
  auto count = [&](const std::string& text) {
    size_t n = 0;
    for (auto at = mended.find(text); at != std::string::npos; at = mended.find(text, at + 1)) ++n;
    return n;
  };
  EXPECT_EQ(count("10.0.0.2 41230"), 1u) << mended;  // already there: not twice
  EXPECT_EQ(count("10.0.0.3 41231"), 1u) << mended;
  EXPECT_EQ(count("10.0.0.4"), 0u) << mended;  // no such m-line
  EXPECT_EQ(count("a=end-of-candidates"), 2u) << mended;
  EXPECT_EQ(answerWithCandidates("not sdp", {}), "not sdp");
}

TEST(WhepSdp, OfMainPayloadTypesOneThatAllowsAnyLevelIsTakenAndItsFormatKept) {
  std::string offered = kOffer;
  offered.replace(offered.find("a=rtpmap:97 rtx/90000"), 0,
                  "a=rtpmap:120 H264/90000\r\n"
                  "a=fmtp:120 packetization-mode=1;profile-level-id=4d0015\r\n"
                  "a=rtpmap:121 H264/90000\r\n"
                  "a=fmtp:121 packetization-mode=1;profile-level-id=4d0028\r\n"
                  "a=rtpmap:116 H264/90000\r\n"
                  "a=fmtp:116 level-asymmetry-allowed=1;packetization-mode=1;"
                  "profile-level-id=4d001f\r\n");
  auto offer = readViewerOffer(offered, {"127.0.0.1"});
  ASSERT_TRUE(offer) << offer.error();
  EXPECT_EQ(offer->h264Payload, 116);
  EXPECT_EQ(offer->h264Format,
            "level-asymmetry-allowed=1;packetization-mode=1;profile-level-id=4d001f");
  // Without one that allows any level, the highest level.
  offered.erase(
      offered.find("level-asymmetry-allowed=1;packetization-mode=1;profile-level-id=4d001f"),
      std::string("level-asymmetry-allowed=1;").size());
  auto highest = readViewerOffer(offered, {"127.0.0.1"});
  ASSERT_TRUE(highest) << highest.error();
  EXPECT_EQ(highest->h264Payload, 121);
}

TEST(WhepSdp, AnAnswerWithoutTheProfileGetsTheOfferedFormat) {
  const std::string answer =
      "v=0\r\no=- 1 0 IN IP4 0.0.0.0\r\ns=-\r\nt=0 0\r\n"
      "m=video 9 UDP/TLS/RTP/SAVPF 116\r\nc=IN IP4 0.0.0.0\r\na=sendonly\r\n"
      "a=rtpmap:116 H264/90000\r\na=fmtp:116 packetization-mode=1\r\n";
  auto mended = answerWithH264Format(
      answer, 116, "level-asymmetry-allowed=1;packetization-mode=1;profile-level-id=4d001f");
  EXPECT_NE(mended.find("a=fmtp:116 level-asymmetry-allowed=1;packetization-mode=1;"
                        "profile-level-id=4d001f\r\n"),
            std::string::npos)
      << mended;
  EXPECT_EQ(mended.find("a=fmtp:116 packetization-mode=1\r\n"), std::string::npos) << mended;
  // One that names its profile (what flows) is left as it is.
  std::string named = answer;
  named.replace(named.find("packetization-mode=1\r\n"), 0, "profile-level-id=4d4014;");
  EXPECT_EQ(answerWithH264Format(named, 116, "profile-level-id=4d001f"), named);
}

}  // namespace
}  // namespace wircam::recorder
