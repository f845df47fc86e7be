// The WebRTC service in this process, serving an H.264 camera whose encoder
// makes non-IDR I-frames between IDRs (scene_cut_h264.h), to a webrtcbin
// viewer we did not write.
// Whenever a viewer joins, the first frame it receives is an IDR with its
// SPS and PPS: an I-frame that is not an IDR is no place for a decoder to
// start (its picture parameter set may be none the viewer has).
#include <gst/gst.h>
#include <gtest/gtest.h>

#include <optional>

#include "camera/frame_tap.h"
#include "common/h264_access_unit.h"
#include "main_loop_until.h"
#include "scene_cut_h264.h"
#include "webrtc/webrtc_service.h"
#include "webrtcbin_viewer.h"

namespace {

using namespace wircam;
using namespace wircam::recorder;
using namespace wircam::testing;
using namespace std::chrono_literals;

TEST(WebRtcH264Start, AViewerJoiningBetweenIdrsStartsOnAnIdrThoughIFramesComeBefore) {
  if (!gst_element_factory_find("avdec_h264") || !gst_element_factory_find("x264enc"))
    GTEST_SKIP() << "x264enc or avdec_h264 (gstreamer1.0-plugins-ugly, -libav) is not installed";
  FrameTap jpeg, encoded;
  GstElement* pipeline = sceneCutH264Into(encoded);
  ASSERT_TRUE(pipeline);
  gst_element_set_state(pipeline, GST_STATE_PLAYING);
  {
    WebRtcService::Settings settings;
    settings.driveMessage = [](const std::string&, std::optional<std::string_view>) {
      return std::string();
    };
    settings.neutral = [](const std::string&) {};
    WebRtcService service({{.name = "rover-cam0", .frames = &jpeg, .h264 = &encoded}}, settings);
    // Viewers one after the other, each joining wherever the stream is.
    for (int round = 0; round < 3; ++round) {
      WebRtcBinViewer viewer(kVp8ThenMain);
      std::optional<Expected<WebRtcService::Answer, WebRtcService::Refusal>> answer;
      service.offer("rover-cam0", viewer.offer(), "127.0.0.1",
                    [&](auto given) { answer = std::move(given); });
      ASSERT_TRUE(runMainLoopUntil([&] { return answer.has_value(); }, 15s)) << "no answer";
      ASSERT_TRUE(*answer) << (*answer).error().why;
      viewer.answer((*answer)->sdp);
      ASSERT_TRUE(runMainLoopUntil([&] { return viewer.decoded() > 0; }, 15s))
          << "round " << round << ": no frame decoded";
      std::string first = viewer.firstAccessUnit();
      EXPECT_TRUE(startsDecoding(first, H264Framing::byteStream()))
          << "round " << round << ": the viewer's first frame is no IDR";
      EXPECT_NE(first.find(std::string("\0\0\1\x67", 4)), std::string::npos)
          << "round " << round << ": no SPS before the first frame";
    }
  }
  gst_element_set_state(pipeline, GST_STATE_NULL);
  encoded.detach();
  gst_object_unref(pipeline);
}

}  // namespace
