// wirc-recorder --rtsp: a GStreamer RTSP client plays each camera.
#include <gst/app/gstappsink.h>
#include <gst/video/video.h>
#include <gtest/gtest.h>

#include "bus_messages.h"
#include "recorder_process.h"
#include "shell_command.h"
#include "simulated_device.h"
#include "wait_for.h"

namespace {

using namespace wircam::testing;
using std::chrono::milliseconds;

// The recorder's RTSP server says what it did with each client (in its
// log, shown when a test fails): whether a client that got no frame was
// refused, or set up its stream and then got no packet (frames stamped
// before the media's base time did that once: rtsp_media_feed.cpp).
const std::vector<std::string> kServerSaysWhatItDoes = {
    "env", "GST_DEBUG=rtspclient:4,rtspmedia:4,rtspstream:4", "GST_DEBUG_NO_COLOR=1"};

TEST(WircRecorderRtsp, AClientPlaysTheCamera) {
  auto device = startSequenceDevice();
  RecorderProcess recorder(device->port(), {"--rtsp", "127.0.0.1:0", "--duration", "60"},
                           kServerSaysWhatItDoes);
  auto url = recorder.waitForLog("rtsp://", milliseconds(10000));
  ASSERT_TRUE(url) << recorder.log();
  EXPECT_NE(url->find("/127.0.0.1-" + std::to_string(device->port()) + "/cam0"), std::string::npos);
  for (const char* protocols : {"udp", "tcp"}) {
    // rtspsrc gives up on UDP after `timeout` µs without a packet (5 s by
    // default); a sanitizer's slower server gets the longer patience.
    auto udpTimeoutUs = patience(milliseconds(5000)).count() * 1000;
    std::string description = "rtspsrc location=" + *url + " protocols=" + protocols +
                              " timeout=" + std::to_string(udpTimeoutUs) +
                              " ! rtpjpegdepay ! jpegdec ! appsink name=sink";
    GstElement* pipeline = gst_parse_launch(description.c_str(), nullptr);
    GstElement* sink = gst_bin_get_by_name(GST_BIN(pipeline), "sink");
    gst_element_set_state(pipeline, GST_STATE_PLAYING);
    int frames = 0;
    int width = 0;
    while (frames < 15) {
      GstSample* sample = gst_app_sink_try_pull_sample(
          GST_APP_SINK(sink), patience(milliseconds(10000)).count() * GST_MSECOND);
      if (!sample) break;
      GstVideoInfo info;
      gst_video_info_from_caps(&info, gst_sample_get_caps(sample));
      width = GST_VIDEO_INFO_WIDTH(&info);
      gst_sample_unref(sample);
      ++frames;
    }
    // What the client's elements said went wrong: "0 frames" alone does
    // not tell a SETUP refused from packets that never came.
    std::string trouble = wircam::testing::busProblems(pipeline);
    gst_element_set_state(pipeline, GST_STATE_NULL);
    gst_object_unref(sink);
    gst_object_unref(pipeline);
    EXPECT_EQ(frames, 15) << protocols << "\n" << trouble << recorder.log();
    EXPECT_EQ(width, 352) << protocols;  // the scene's CIF frames, decoded
  }
}

// With --http-token the RTSP server asks for the same credentials: Basic,
// the token as the password, any user name.
TEST(WircRecorderRtsp, WithATokenOnlyAClientWithItPlays) {
  constexpr const char* kToken = "0123456789abcdef0123456789abcdef";
  auto device = startSequenceDevice();
  RecorderProcess recorder(device->port(),
                           {"--rtsp", "127.0.0.1:0", "--http", "127.0.0.1:0", "--http-token",
                            kToken, "--duration", "60"},
                           kServerSaysWhatItDoes);
  auto url = recorder.waitForLog("rtsp://", milliseconds(10000));
  ASSERT_TRUE(url) << recorder.log();
  auto play = [&](const std::string& credentials) {
    std::string location = "rtsp://" + credentials + url->substr(7);
    // (rtspsrc's own account of the exchange, for a client that gets no
    // frame: without it, gst-launch's exit code alone says nothing.)
    return runCommand(
        "GST_DEBUG=rtspsrc:4 GST_DEBUG_NO_COLOR=1 timeout 20 gst-launch-1.0 -q "
        "rtspsrc location='" +
        location + "' protocols=tcp ! rtpjpegdepay ! jpegdec ! fakesink num-buffers=5 2>&1");
  };
  auto played = play(std::string("viewer:") + kToken + "@");
  EXPECT_EQ(played.exitCode, 0) << played.output << recorder.log();
  auto anonymous = play("");
  EXPECT_NE(anonymous.exitCode, 0);
  EXPECT_NE(anonymous.output.find("Unauthorized"), std::string::npos) << anonymous.output;
  auto wrong = play("viewer:0123456789abcdef0123456789abcdeX@");
  EXPECT_NE(wrong.exitCode, 0);
  EXPECT_NE(wrong.output.find("Unauthorized"), std::string::npos) << wrong.output;
}

}  // namespace
