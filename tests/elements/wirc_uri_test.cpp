// wircsrc as a URI handler: wirc://HOST[:PORT]/CAMERA?device=NAME, for
// playbin and gst-play-1.0, against the simulated device.
#include <gst/gst.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <memory>
#include <regex>
#include <thread>

#include "devices/wirc/device.h"
#include "jpeg_sequence_scene.h"
#include "pipelines.h"
#include "scene_frames.h"

namespace wircam {
namespace {

using testing::sceneFrames;

std::unique_ptr<wirc::Device> startDevice() {
  auto device = wirc::Device::start({.port = 0, .fragmentSize = 8000},
                                    std::make_shared<sim::JpegSequenceScene>(sceneFrames()));
  return device ? std::move(*device) : nullptr;
}

TEST(WircUri, SetsHostPortCameraAndDevice) {
  GError* error = nullptr;
  GstElement* source = gst_element_make_from_uri(
      GST_URI_SRC, "wirc://192.168.1.1:2000/1?device=rover%201", nullptr, &error);
  ASSERT_NE(source, nullptr) << (error ? error->message : "");
  EXPECT_STREQ(G_OBJECT_TYPE_NAME(source), "GstWircSrc");
  gchar *host = nullptr, *device = nullptr;
  guint port = 0, camera = 0;
  g_object_get(source, "host", &host, "port", &port, "camera", &camera, "device", &device, nullptr);
  EXPECT_STREQ(host, "192.168.1.1");
  EXPECT_EQ(port, 2000u);
  EXPECT_EQ(camera, 1u);
  EXPECT_STREQ(device, "rover 1");
  gchar* uri = gst_uri_handler_get_uri(GST_URI_HANDLER(source));
  EXPECT_STREQ(uri, "wirc://192.168.1.1:2000/1?device=rover%201");
  g_free(uri);
  g_free(host);
  g_free(device);
  // Discovery: no host, a device name; the port and camera default.
  EXPECT_TRUE(gst_uri_handler_set_uri(GST_URI_HANDLER(source), "wirc:///?device=rover", nullptr));
  g_object_get(source, "host", &host, "port", &port, "camera", &camera, nullptr);
  EXPECT_STREQ(host, "");
  EXPECT_EQ(port, 1984u);
  EXPECT_EQ(camera, 0u);
  g_free(host);
  gst_object_unref(source);
}

TEST(WircUri, RefusesWhatIsNotAWircCamera) {
  GstElement* source = gst_element_factory_make("wircsrc", nullptr);
  GError* foreign = nullptr;
  EXPECT_FALSE(gst_uri_handler_set_uri(GST_URI_HANDLER(source), "http://192.168.1.1/0", &foreign));
  ASSERT_NE(foreign, nullptr);
  g_error_free(foreign);
  for (const char* bad :
       {"wirc://192.168.1.1/cam", "wirc://h/300", "wirc://h:70000/0", "wirc://h/0?speed=3"}) {
    GError* error = nullptr;
    EXPECT_FALSE(gst_uri_handler_set_uri(GST_URI_HANDLER(source), bad, &error)) << bad;
    ASSERT_NE(error, nullptr) << bad;
    EXPECT_NE(std::string(error->message).find("wirc://HOST[:PORT]/CAMERA"), std::string::npos)
        << error->message;
    g_error_free(error);
  }
  gst_object_unref(source);
}

TEST(WircUri, PlaybinPlaysTheCamera) {
  auto device = startDevice();
  ASSERT_TRUE(device);
  std::string uri = "wirc://127.0.0.1:" + std::to_string(device->port()) + "/0";
  GstElement* playbin = gst_element_factory_make("playbin", nullptr);
  GstElement* sink = gst_element_factory_make("fakesink", nullptr);
  g_object_set(sink, "signal-handoffs", TRUE, "sync", FALSE, nullptr);
  static std::atomic<int> frames;
  frames = 0;
  g_signal_connect(sink, "handoff",
                   G_CALLBACK(+[](GstElement*, GstBuffer*, GstPad*, gpointer) { ++frames; }),
                   nullptr);
  g_object_set(playbin, "uri", uri.c_str(), "video-sink", sink, nullptr);
  gst_element_set_state(playbin, GST_STATE_PLAYING);
  for (int i = 0; i < 300 && frames < 10; ++i)
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  EXPECT_GE(frames, 10) << "decoded frames at playbin's video sink";
  gst_element_set_state(playbin, GST_STATE_NULL);
  gst_object_unref(playbin);
}

TEST(WircUri, GstPlayPlaysItWithAFakeVideoSink) {
  auto device = startDevice();
  ASSERT_TRUE(device);
  // Its input is no terminal: run from one (tools/run-tests typed in a
  // shell), gst-play set it up for its keys from the background process
  // group timeout puts it in, was stopped for that (SIGTTOU), and printed
  // nothing.
  std::string output = testing::commandOutput(
      std::string("GST_PLUGIN_PATH=") + WIRCAM_PLUGIN_DIR +
      " timeout -s INT 3 gst-play-1.0 --videosink=fakesink wirc://127.0.0.1:" +
      std::to_string(device->port()) + "/0 < /dev/null");
  EXPECT_NE(output.find("Now playing wirc://127.0.0.1:"), std::string::npos) << output;
  EXPECT_NE(output.find("Prerolled"), std::string::npos) << output;
  // gst-play prints the position every ~100 ms ("0:00:01.2 / 99:99:99.");
  // a slow machine may skip any one of them.
  double furthest = 0;
  std::regex position(R"((\d+):(\d\d):(\d\d\.\d) / )");
  for (std::sregex_iterator it(output.begin(), output.end(), position), end; it != end; ++it)
    furthest = std::max(
        furthest, std::stoi((*it)[1]) * 3600.0 + std::stoi((*it)[2]) * 60.0 + std::stod((*it)[3]));
  EXPECT_GE(furthest, 1.0) << "the position never reached 1 s\n" << output;
  EXPECT_EQ(output.find("ERROR"), std::string::npos) << output;
}

}  // namespace
}  // namespace wircam
