// wircsrc in real pipelines against the simulated device on loopback.
#include <gst/check/gstharness.h>
#include <gst/gst.h>
#include <gtest/gtest.h>

#include <future>
#include <thread>

#include "buffer_bytes.h"
#include "devices/wirc/device.h"
#include "jpeg_sequence_scene.h"
#include "pipelines.h"
#include "scene_frames.h"
#include "wait_for.h"
#include "wirc/transmitter_session.h"

namespace {

using namespace wircam;
using std::chrono::milliseconds;
using wircam::testing::busMessage;
using wircam::testing::firstErrorOf;
using wircam::testing::isSceneFrame;
using wircam::testing::launch;
using wircam::testing::sceneFrames;
using wircam::testing::waitFor;

std::unique_ptr<wirc::Device> startDevice(wirc::DeviceConfig config = {}) {
  config.fps = 30;
  auto device =
      wirc::Device::start(config, std::make_shared<sim::JpegSequenceScene>(sceneFrames()));
  EXPECT_TRUE(device.has_value()) << device.error();
  return std::move(*device);
}

wirc::DeviceConfig ephemeral(wirc::DeviceConfig config = {}) {
  config.port = 0;
  return config;
}

guint64 stat(GstElement* element, const char* name) {
  GstStructure* stats = nullptr;
  g_object_get(element, "stats", &stats, nullptr);
  guint64 value = 0;
  gst_structure_get_uint64(stats, name, &value);
  gst_structure_free(stats);
  return value;
}

class WircSrcHarness {
 public:
  explicit WircSrcHarness(uint16_t port, int camera = 0) {
    harness_ = gst_harness_new("wircsrc");
    g_object_set(harness_->element, "host", "127.0.0.1", "port", static_cast<guint>(port), "camera",
                 static_cast<guint>(camera), nullptr);
    gst_harness_play(harness_);
  }
  ~WircSrcHarness() { gst_harness_teardown(harness_); }

  GstBuffer* pull(milliseconds timeout = milliseconds(3000)) {
    auto end = std::chrono::steady_clock::now() + timeout;
    while (std::chrono::steady_clock::now() < end) {
      if (GstBuffer* buffer = gst_harness_try_pull(harness_)) return buffer;
      std::this_thread::sleep_for(milliseconds(5));
    }
    return nullptr;
  }
  std::vector<uint8_t> pullBytes(milliseconds timeout = milliseconds(3000)) {
    GstBuffer* buffer = pull(timeout);
    if (!buffer) return {};
    auto bytes = bufferBytes(buffer);
    gst_buffer_unref(buffer);
    return bytes;
  }
  GstElement* element() const { return harness_->element; }
  GstHarness* harness() const { return harness_; }

 private:
  GstHarness* harness_;
};

TEST(WircSrc, DeliversTheSimulatorsFramesByteForByteWithCaps) {
  auto device = startDevice(ephemeral({.fragmentSize = 1400}));
  WircSrcHarness src(device->port());
  for (int i = 0; i < 20; ++i) {
    auto frame = src.pullBytes();
    ASSERT_FALSE(frame.empty()) << "frame " << i;
    EXPECT_TRUE(isSceneFrame(frame)) << "frame " << i;
  }
  GstCaps* caps = gst_pad_get_current_caps(src.harness()->sinkpad);
  ASSERT_NE(caps, nullptr);
  int width = 0;
  gst_structure_get_int(gst_caps_get_structure(caps, 0), "width", &width);
  EXPECT_EQ(width, 352);
  gst_caps_unref(caps);
}

TEST(WircSrc, DeliversAtLeast95PercentOfWholeFramesAtFivePercentLoss) {
  auto device =
      startDevice(ephemeral({.fragmentSize = 1400, .impairments = {.loss = 0.05, .seed = 5}}));
  WircSrcHarness src(device->port());
  uint64_t delivered = 0;
  auto end = std::chrono::steady_clock::now() + milliseconds(3000);
  while (std::chrono::steady_clock::now() < end) {
    auto frame = src.pullBytes(milliseconds(500));
    if (frame.empty()) continue;
    EXPECT_TRUE(isSceneFrame(frame));
    ++delivered;
  }
  uint64_t whole = device->stats().framesSentWhole;
  ASSERT_GT(whole, 20u);
  EXPECT_GE(static_cast<double>(delivered) + 2, 0.95 * static_cast<double>(whole))
      << delivered << " delivered of " << whole << " sent whole";
  EXPECT_GT(stat(src.element(), "frames-incomplete"), 0u);
}

TEST(WircSrc, TwoCamerasShareOneLoginAndStopSendsEst) {
  auto device = startDevice(ephemeral({.cameras = 2, .fragmentSize = 8000}));
  auto port = std::to_string(device->port());
  GstElement* pipeline =
      launch("wircsrc name=a host=127.0.0.1 camera=0 port=" + port +
             " ! fakesink wircsrc name=b host=127.0.0.1 camera=1 port=" + port + " ! fakesink");
  gst_element_set_state(pipeline, GST_STATE_PLAYING);
  GstElement* a = gst_bin_get_by_name(GST_BIN(pipeline), "a");
  GstElement* b = gst_bin_get_by_name(GST_BIN(pipeline), "b");
  EXPECT_TRUE(
      waitFor([&] { return stat(a, "frames-complete") > 5 && stat(b, "frames-complete") > 5; }));
  EXPECT_EQ(busMessage(pipeline, milliseconds(0)), "");
  EXPECT_EQ(device->stats().logins, 1u);
  EXPECT_EQ(device->stats().activeStreams, 2u);
  gst_element_set_state(pipeline, GST_STATE_NULL);
  gst_object_unref(a);
  gst_object_unref(b);
  gst_object_unref(pipeline);
  EXPECT_TRUE(waitFor([&] { return device->stats().activeStreams == 0; }));
}

TEST(WircSrc, ReportsAnUnreachableDevice) {
  auto device = startDevice(ephemeral());
  auto port = std::to_string(device->port());
  device.reset();
  auto error = firstErrorOf("wircsrc host=127.0.0.1 reconnect=false port=" + port + " ! fakesink",
                            milliseconds(5000));
  EXPECT_NE(error.find("Could not log in"), std::string::npos) << error;
}

TEST(WircSrc, WaitingForADeviceWithoutReconnectingIsRefusedWithTheReason) {
  // It failed at the first refused connection, as "Could not log in" only.
  auto device = startDevice(ephemeral());
  auto port = std::to_string(device->port());
  device.reset();
  auto error = firstErrorOf(
      "wircsrc host=127.0.0.1 wait-for-device=true reconnect=false port=" + port + " ! fakesink",
      milliseconds(5000));
  EXPECT_NE(error.find("wait-for-device=true needs reconnect=true"), std::string::npos) << error;
}

TEST(WircSrc, ReportsACameraTheDeviceDoesNotHave) {
  auto device = startDevice(ephemeral({.cameras = 1}));
  auto error = firstErrorOf(
      "wircsrc host=127.0.0.1 camera=3 port=" + std::to_string(device->port()) + " ! fakesink",
      milliseconds(5000));
  EXPECT_NE(error.find("no camera 3"), std::string::npos) << error;
}

TEST(WircSrc, ACameraTheDeviceLacksFailsAloneAndItsSiblingStreamsOn) {
  // As the recorder runs them: a pipeline per camera, one link per device.
  // The device's refusal of camera 5 (an ERR names no camera) failed
  // camera 0 too, at each of camera 5's retries (a stranger's trial).
  auto device = startDevice(ephemeral({.cameras = 2, .fragmentSize = 8000}));
  auto port = std::to_string(device->port());
  GstElement* present =
      launch("wircsrc name=src host=127.0.0.1 camera=0 port=" + port + " ! fakesink");
  gst_element_set_state(present, GST_STATE_PLAYING);
  GstElement* src = gst_bin_get_by_name(GST_BIN(present), "src");
  ASSERT_TRUE(waitFor([&] { return stat(src, "frames-complete") > 2; }));
  for (int retry = 0; retry < 3; ++retry) {
    auto error = firstErrorOf("wircsrc host=127.0.0.1 camera=5 port=" + port + " ! fakesink",
                              milliseconds(5000));
    EXPECT_NE(error.find("no camera 5"), std::string::npos) << error;
  }
  auto before = stat(src, "frames-complete");
  EXPECT_TRUE(waitFor([&] { return stat(src, "frames-complete") > before + 5; }));
  EXPECT_EQ(busMessage(present, milliseconds(0)), "");
  EXPECT_EQ(device->stats().errSent, 0u);
  gst_element_set_state(present, GST_STATE_NULL);
  gst_object_unref(src);
  gst_object_unref(present);
}

TEST(WircSrc, FollowsTheDeviceThroughARestart) {
  auto device = startDevice(ephemeral({.fragmentSize = 4000}));
  uint16_t port = device->port();
  WircSrcHarness src(port);
  ASSERT_FALSE(src.pullBytes().empty());
  device.reset();
  // The shared link (joined here) has noticed: what is queued came before.
  auto shared = wirc::TransmitterSession::acquire({.host = "127.0.0.1", .port = port});
  ASSERT_TRUE(shared.has_value());
  ASSERT_TRUE(waitFor([&] { return (*shared)->status().state != link::LinkState::Live; }));
  while (gst_harness_buffers_in_queue(src.harness()) > 0)
    gst_buffer_unref(gst_harness_pull(src.harness()));
  device = startDevice({.port = port, .fragmentSize = 4000});
  auto frame = src.pullBytes(milliseconds(8000));
  ASSERT_FALSE(frame.empty());
  EXPECT_TRUE(isSceneFrame(frame));
}

TEST(WircSrc, PcdKeepsFlowingWhileThePipelineIsBlocked) {
  auto device = startDevice(ephemeral());
  GstElement* pipeline = launch(
      "wircsrc name=src host=127.0.0.1 port=" + std::to_string(device->port()) + " ! fakesink");
  GstElement* src = gst_bin_get_by_name(GST_BIN(pipeline), "src");
  GstPad* pad = gst_element_get_static_pad(src, "src");
  // The first buffer blocks the streaming thread until the probe goes, as a
  // stalled pipeline would.
  gulong probe = gst_pad_add_probe(
      pad, GST_PAD_PROBE_TYPE_BLOCK_DOWNSTREAM,
      [](GstPad*, GstPadProbeInfo*, gpointer) { return GST_PAD_PROBE_OK; }, nullptr, nullptr);
  gst_element_set_state(pipeline, GST_STATE_PLAYING);
  // Keepalives from the event loop, not the stalled thread: the device's
  // watchdog (800 ms) never fires. The largest gap is in bench_control_latency.
  EXPECT_TRUE(waitFor([&] { return device->stats().pcdReceived > 20; }));
  EXPECT_EQ(device->stats().failsafeEntries, 0u);
  gst_pad_remove_probe(pad, probe);
  gst_element_set_state(pipeline, GST_STATE_NULL);
  gst_object_unref(pad);
  gst_object_unref(src);
  gst_object_unref(pipeline);
}

TEST(WircSrc, EndOfStreamNeverWaitsForAThreadHeldDownstreamAndEndsTheStreamAfterIt) {
  auto device = startDevice(ephemeral());
  GstElement* pipeline = launch(
      "wircsrc name=src host=127.0.0.1 port=" + std::to_string(device->port()) + " ! fakesink");
  GstElement* src = gst_bin_get_by_name(GST_BIN(pipeline), "src");
  GstPad* pad = gst_element_get_static_pad(src, "src");
  // The first frame is held, as a muxer waiting for another input holds it.
  std::promise<void> held;
  gulong block = gst_pad_add_probe(
      pad, static_cast<GstPadProbeType>(GST_PAD_PROBE_TYPE_BLOCK | GST_PAD_PROBE_TYPE_BUFFER),
      [](GstPad*, GstPadProbeInfo*, gpointer promise) {
        static_cast<std::promise<void>*>(promise)->set_value();
        return GST_PAD_PROBE_OK;
      },
      &held, nullptr);
  gst_element_set_state(pipeline, GST_STATE_PLAYING);
  ASSERT_EQ(held.get_future().wait_for(std::chrono::seconds(5)), std::future_status::ready);
  // (gst_element_send_event(EOS) would wait here for as long as the frame
  // is held: basesrc takes the stream lock for it.)
  auto ended =
      std::async(std::launch::async, [src] { g_signal_emit_by_name(src, "end-of-stream"); });
  EXPECT_EQ(ended.wait_for(milliseconds(1000)), std::future_status::ready);
  gst_pad_remove_probe(pad, block);
  GstBus* bus = gst_element_get_bus(pipeline);
  GstMessage* eos = gst_bus_timed_pop_filtered(
      bus, 3 * GST_SECOND, static_cast<GstMessageType>(GST_MESSAGE_EOS | GST_MESSAGE_ERROR));
  ASSERT_NE(eos, nullptr);
  EXPECT_EQ(GST_MESSAGE_TYPE(eos), GST_MESSAGE_EOS);
  gst_message_unref(eos);
  gst_object_unref(bus);
  ended.wait();
  gst_element_set_state(pipeline, GST_STATE_NULL);
  gst_object_unref(pad);
  gst_object_unref(src);
  gst_object_unref(pipeline);
}

}  // namespace
