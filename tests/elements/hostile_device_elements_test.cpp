// wircsrc against broken and hostile devices: a junk flood at start, a
// refused stream, a status report that stops, a name the protocol cannot
// carry.
#include <gst/gst.h>
#include <gtest/gtest.h>

#include <atomic>
#include <thread>

#include "devices/wirc/device.h"
#include "jpeg_sequence_scene.h"
#include "misbehaving_peers.h"
#include "pipelines.h"
#include "scene_frames.h"
#include "wait_for.h"

namespace {

using namespace wircam;
using std::chrono::milliseconds;
using wircam::testing::busMessage;
using wircam::testing::firstErrorOf;
using wircam::testing::launch;
using wircam::testing::waitFor;

guint64 framesOf(GstElement* pipeline) {
  GstElement* src = gst_bin_get_by_name(GST_BIN(pipeline), "src");
  GstStructure* stats = nullptr;
  g_object_get(src, "stats", &stats, nullptr);
  guint64 frames = 0;
  gst_structure_get_uint64(stats, "frames-complete", &frames);
  gst_structure_free(stats);
  gst_object_unref(src);
  return frames;
}

uint16_t freeUdpPort() {
  auto fd = bindUdp(SocketAddress::loopback(0));
  return localAddress(fd->get()).port();
}

TEST(HostileDeviceElements, AJunkFloodFromTheDevicesAddressCannotClaimTheStream) {
  auto device =
      wirc::Device::start({.port = 0, .fps = 30},
                          std::make_shared<sim::JpegSequenceScene>(wircam::testing::sceneFrames()));
  ASSERT_TRUE(device.has_value());
  uint16_t streamPort = freeUdpPort();
  // Junk from the device's own address, another port, before the stream
  // starts and all along.
  std::atomic<bool> flooding{true};
  std::thread flood([&] {
    auto junk = bindUdp(SocketAddress::loopback(0));
    std::vector<uint8_t> garbage(200, 0x42);
    while (flooding) {
      sendDatagram(junk->get(), SocketAddress::loopback(streamPort), garbage);
      std::this_thread::sleep_for(std::chrono::microseconds(200));
    }
  });
  std::this_thread::sleep_for(milliseconds(50));
  GstElement* pipeline =
      launch("wircsrc name=src host=127.0.0.1 port=" + std::to_string((*device)->port()) +
             " stream-port=" + std::to_string(streamPort) + " ! fakesink");
  gst_element_set_state(pipeline, GST_STATE_PLAYING);
  EXPECT_TRUE(waitFor([&] { return framesOf(pipeline) >= 10; }));
  flooding = false;
  flood.join();
  gst_element_set_state(pipeline, GST_STATE_NULL);
  gst_object_unref(pipeline);
}

TEST(HostileDeviceElements, ARefusedStreamEndsTheStreamWithTheDevicesReason) {
  wircam::testing::ScriptedPeer peer;
  peer.play({.chunks = {peer.wst(), wircam::testing::bytesOf(
                                        wirc::Err{static_cast<uint8_t>(wirc::Command::Stst),
                                                  static_cast<uint16_t>(wirc::ErrorCode::Busy)})}});
  auto error =
      firstErrorOf("wircsrc host=127.0.0.1 port=" + std::to_string(peer.port()) + " ! fakesink",
                   milliseconds(3000));
  EXPECT_NE(error.find("refused camera 0"), std::string::npos) << error;
  EXPECT_NE(error.find("busy"), std::string::npos) << error;
}

TEST(HostileDeviceElements, AStatusTheDeviceStoppedRenewingIsMarkedStaleWithItsAge) {
  wircam::testing::ScriptedPeer peer;
  peer.play({.chunks = {peer.wst()}, .statusReports = 1});
  GstElement* pipeline =
      launch("wircsrc host=127.0.0.1 link-timeout=10000 stats-interval=200 port=" +
             std::to_string(peer.port()) + " ! fakesink");
  gst_element_set_state(pipeline, GST_STATE_PLAYING);
  GstBus* bus = gst_element_get_bus(pipeline);
  bool fresh = false, stale = false;
  guint64 age = 0;
  EXPECT_TRUE(waitFor(
      [&] {
        while (GstMessage* m = gst_bus_pop_filtered(bus, GST_MESSAGE_ELEMENT)) {
          const GstStructure* s = gst_message_get_structure(m);
          gboolean isStale;
          if (gst_structure_has_name(s, "wirc-stats") &&
              gst_structure_get_boolean(s, "status-stale", &isStale)) {
            (isStale ? stale : fresh) = true;
            gst_structure_get_uint64(s, "status-age-ms", &age);
          }
          gst_message_unref(m);
        }
        return stale;
      },
      milliseconds(5000)));
  EXPECT_TRUE(fresh);  // it was current first
  EXPECT_GT(age, 1000u);
  gst_object_unref(bus);
  gst_element_set_state(pipeline, GST_STATE_NULL);
  gst_object_unref(pipeline);
}

TEST(HostileDeviceElements, ANameTheProtocolCannotCarryIsRefusedWhenSet) {
  GstElement* src = gst_element_factory_make("wircsrc", nullptr);
  g_object_set(src, "transmitter-name", "Pál’s iPhone", nullptr);
  gchar* name = nullptr;
  g_object_get(src, "transmitter-name", &name, nullptr);
  EXPECT_STREQ(name, "wircam");
  g_free(name);
  gst_object_unref(src);
}

}  // namespace
