// wircsrc and wirccontrol over the shared vehicle link: teardown that never
// waits on the network, settings that agree or say why, losses that end
// the stream when reconnect is off, and the control right made visible.
#include <gst/check/gstharness.h>
#include <gst/gst.h>
#include <gtest/gtest.h>

#include "devices/wirc/device.h"
#include "misbehaving_peers.h"
#include "pipelines.h"
#include "vehicle_control.h"
#include "wait_for.h"
#include "wirc/transmitter_session.h"
#include "wirc_tag_meta.h"

namespace {

using namespace wircam;
using std::chrono::milliseconds;
using wircam::testing::busMessage;
using wircam::testing::firstErrorOf;
using wircam::testing::launch;
using wircam::testing::waitFor;

std::unique_ptr<wirc::Device> startDevice(wirc::DeviceConfig config = {}) {
  config.port = 0;
  auto device = wirc::Device::start(config, nullptr);
  EXPECT_TRUE(device.has_value()) << device.error();
  return std::move(*device);
}

milliseconds timeToNull(GstElement* pipeline) {
  auto before = std::chrono::steady_clock::now();
  gst_element_set_state(pipeline, GST_STATE_NULL);
  return std::chrono::duration_cast<milliseconds>(std::chrono::steady_clock::now() - before);
}

// Whatever the network does, going to NULL returns within 500 ms.
void expectQuickTeardown(uint16_t port) {
  auto p = std::to_string(port);
  GstElement* pipeline = launch("wircsrc name=src host=127.0.0.1 login-timeout=10000 port=" + p +
                                " ! wirccontrol host=127.0.0.1 port=" + p + " ! fakesink");
  gst_element_set_state(pipeline, GST_STATE_PLAYING);
  // Mid-login: the source's streaming thread waits for the link.
  GstElement* src = gst_bin_get_by_name(GST_BIN(pipeline), "src");
  EXPECT_TRUE(waitFor([&] { return GST_STATE(src) == GST_STATE_PLAYING; }));
  gst_object_unref(src);
  EXPECT_LT(timeToNull(pipeline).count(), 500);
  gst_object_unref(pipeline);
}

TEST(VehicleLinkElements, StopsAtOnceAgainstAPeerThatAcceptsButNeverAnswers) {
  wircam::testing::SilentPeer peer;
  expectQuickTeardown(peer.port());
}

TEST(VehicleLinkElements, StopsAtOnceWhileAConnectIsStuckInAFullAcceptQueue) {
  wircam::testing::FullAcceptQueuePeer peer;
  expectQuickTeardown(peer.port());
}

TEST(VehicleLinkElements, StopsAtOnceAgainstADeadPort) {
  expectQuickTeardown(wircam::testing::deadPort());
}

TEST(VehicleLinkElements, ARefusedLoginIsAWarningAtOnceAndTheErrorNamesTheRefusal) {
  using wircam::testing::bytesOf;
  wircam::testing::ScriptedPeer peer(
      {.chunks = {bytesOf(wirc::Err{static_cast<uint8_t>(wirc::Command::Tl),
                                    static_cast<uint16_t>(wirc::ErrorCode::Unauthorised)})}});
  // reconnect=true, the default: the link retries, the element says why.
  GstElement* pipeline =
      launch("wircsrc host=127.0.0.1 login-timeout=1500 port=" + std::to_string(peer.port()) +
             " ! fakesink");
  auto start = std::chrono::steady_clock::now();
  gst_element_set_state(pipeline, GST_STATE_PLAYING);
  std::string warning = busMessage(pipeline, wircam::testing::patience(milliseconds(1000)),
                                   GstMessageType(GST_MESSAGE_WARNING | GST_MESSAGE_ERROR));
  auto warned = std::chrono::steady_clock::now() - start;
  EXPECT_NE(warning.find("refused the login: unauthorised"), std::string::npos) << warning;
  EXPECT_NE(warning.find("(ERR 5)"), std::string::npos) << warning;
  EXPECT_LT(warned, wircam::testing::patience(milliseconds(1000)));
  // No login by the deadline: the error names the device's answer.
  std::string error = busMessage(pipeline, wircam::testing::patience(milliseconds(5000)));
  EXPECT_NE(error.find("refused the login: unauthorised"), std::string::npos) << error;
  EXPECT_EQ(error.find("Check host/port"), std::string::npos) << error;
  EXPECT_GE(peer.connections(), 2) << "retried";
  gst_element_set_state(pipeline, GST_STATE_NULL);
  gst_object_unref(pipeline);
}

TEST(VehicleLinkElements, ASinkStartingFirstDoesNotOverrideTheSourcesLoginSettings) {
  auto device = startDevice();
  auto port = std::to_string(device->port());
  // wirccontrol (nearer the sink) acquires the link first and names no
  // login settings; wircsrc names them, and the device must see them.
  GstElement* pipeline =
      launch("wircsrc transmitter-name=alice priority=7 host=127.0.0.1 port=" + port +
             " ! wirccontrol host=127.0.0.1 port=" + port + " ! fakesink");
  gst_element_set_state(pipeline, GST_STATE_PLAYING);
  auto other = wirc::TransmitterSession::acquire(
      {.host = "localhost", .port = device->port(), .transmitterName = "observer"});
  ASSERT_TRUE(other.has_value());
  ASSERT_EQ((*other)->waitLoggedIn(milliseconds(3000)), std::nullopt);
  std::optional<std::vector<wirc::TransmitterInfo>> list;
  EXPECT_TRUE(waitFor([&] {
    list = (*other)->listTransmitters(milliseconds(500));
    return list && list->size() == 2;
  }));
  ASSERT_TRUE(list.has_value());
  bool alice = false;
  for (const auto& t : *list) alice = alice || (t.name == "alice" && t.priority == 7);
  EXPECT_TRUE(alice);
  gst_element_set_state(pipeline, GST_STATE_NULL);
  gst_object_unref(pipeline);
}

TEST(VehicleLinkElements, TwoElementsGivingTheSameDeviceDifferentNamesIsAnErrorNamingBoth) {
  auto device = startDevice({.cameras = 2});
  auto port = std::to_string(device->port());
  auto error = firstErrorOf(
      "wircsrc name=first transmitter-name=alice camera=0 host=127.0.0.1 port=" + port +
          " ! fakesink wircsrc name=second transmitter-name=bob camera=1 host=127.0.0.1 port=" +
          port + " ! fakesink",
      milliseconds(3000));
  for (const char* part : {"transmitter-name", "'alice'", "'bob'", "first", "second"})
    EXPECT_NE(error.find(part), std::string::npos) << error;
}

TEST(VehicleLinkElements, LosingTheDeviceWithReconnectOffEndsTheStreamWithTheCause) {
  auto device = startDevice();
  GstElement* pipeline =
      launch("wircsrc host=127.0.0.1 reconnect=false port=" + std::to_string(device->port()) +
             " ! fakesink");
  gst_element_set_state(pipeline, GST_STATE_PLAYING);
  ASSERT_TRUE(waitFor([&] { return device->stats().activeStreams == 1; }));
  device.reset();
  auto error = busMessage(pipeline, milliseconds(3000));
  EXPECT_NE(error.find("Lost the WiRC device"), std::string::npos) << error;
  EXPECT_NE(error.find("closed the connection"), std::string::npos) << error;
  gst_element_set_state(pipeline, GST_STATE_NULL);
  gst_object_unref(pipeline);
}

TEST(VehicleLinkElements, ASettingChangedWhileStreamingIsRefused) {
  auto device = startDevice();
  GstElement* pipeline =
      launch("wircsrc name=src camera=0 host=127.0.0.1 port=" + std::to_string(device->port()) +
             " ! fakesink");
  gst_element_set_state(pipeline, GST_STATE_PLAYING);
  GstElement* src = gst_bin_get_by_name(GST_BIN(pipeline), "src");
  ASSERT_TRUE(waitFor([&] { return GST_STATE(src) == GST_STATE_PLAYING; }));
  g_object_set(src, "camera", 1u, nullptr);
  guint camera = 99;
  g_object_get(src, "camera", &camera, nullptr);
  EXPECT_EQ(camera, 0u);
  gst_object_unref(src);
  gst_element_set_state(pipeline, GST_STATE_NULL);
  gst_object_unref(pipeline);
}

// A buffer with one tag off to the left: the follower steers (once the
// stream's time moves on between such buffers).
GstBuffer* bufferWithATag(GstClockTime pts) {
  GstBuffer* buffer = gst_buffer_new_allocate(nullptr, 16, nullptr);
  GST_BUFFER_PTS(buffer) = pts;
  WircTagMeta* meta = gst_buffer_add_wirc_tag_meta(buffer, 352, 288);
  WircTag tag{};
  tag.id = 0;
  tag.cx = 60;
  tag.cy = 144;
  double corners[8] = {40, 124, 80, 124, 80, 164, 40, 164};
  std::copy(corners, corners + 8, tag.corners);
  g_array_append_val(meta->tags, tag);
  return buffer;
}

TEST(VehicleLinkElements, WirccontrolShowsTheControlRightAndTheAnswerToARequest) {
  auto device = startDevice();
  // Another transmitter of higher priority logs in first and holds the right.
  auto boss = wirc::TransmitterSession::acquire(
      {.host = "localhost", .port = device->port(), .transmitterName = "boss", .priority = 9});
  ASSERT_TRUE(boss.has_value());
  ASSERT_EQ((*boss)->waitLoggedIn(milliseconds(3000)), std::nullopt);
  ASSERT_TRUE(waitFor([&] { return (*boss)->status().hasControl; }));

  // Properties before the harness activates the pads (which starts the element).
  auto description = "wirccontrol host=127.0.0.1 port=" + std::to_string(device->port());
  GstHarness* h = gst_harness_new_parse(description.c_str());
  GstElement* control = gst_harness_find_element(h, "wirccontrol");
  GstBus* bus = gst_bus_new();
  gst_element_set_bus(h->element, bus);
  gst_harness_set_src_caps_str(h, "video/x-raw,format=GRAY8,width=352,height=288");
  gst_harness_play(h);
  ASSERT_TRUE(waitFor([&] { return device->stats().logins == 2; }));

  // Steering without the right: one warning, and has-control says so.
  for (int i = 0; i < 3; ++i)
    gst_buffer_unref(gst_harness_push_and_pull(h, bufferWithATag(i * 66 * GST_MSECOND)));
  gboolean hasControl = TRUE;
  g_object_get(control, "has-control", &hasControl, nullptr);
  EXPECT_FALSE(hasControl);
  int warnings = 0;
  while (GstMessage* m = gst_bus_pop_filtered(bus, GST_MESSAGE_WARNING)) {
    ++warnings;
    gst_message_unref(m);
  }
  EXPECT_EQ(warnings, 1);

  // Asking for it: the device says no, and says who holds it.
  g_signal_emit_by_name(control, "request-control");
  GstStructure* answer = nullptr;
  EXPECT_TRUE(waitFor([&] {
    while (GstMessage* m = gst_bus_pop_filtered(bus, GST_MESSAGE_ELEMENT)) {
      const GstStructure* s = gst_message_get_structure(m);
      if (gst_structure_has_name(s, "wirc-control-right") && gst_structure_has_field(s, "request"))
        answer = gst_structure_copy(s);
      gst_message_unref(m);
    }
    return answer != nullptr;
  }));
  ASSERT_NE(answer, nullptr);
  EXPECT_STREQ(gst_structure_get_string(answer, "request"), "denied");
  EXPECT_NE(std::string(gst_structure_get_string(answer, "reason")).find("boss"),
            std::string::npos);
  gst_structure_free(answer);

  // The boss hands it over: has-control follows.
  auto transmitters = (*boss)->listTransmitters(milliseconds(1000));
  ASSERT_TRUE(transmitters.has_value());
  for (const auto& t : *transmitters)
    if (t.name != "boss") (*boss)->requestControlFor(t.connectionId);
  EXPECT_TRUE(waitFor([&] {
    g_object_get(control, "has-control", &hasControl, nullptr);
    return hasControl == TRUE;
  }));
  gst_object_unref(control);
  gst_harness_teardown(h);
  gst_object_unref(bus);
}

// The first `wirc-vehicle` link state `pipeline` posts within 3 s (longer
// under a sanitizer).
std::string firstVehicleState(GstElement* pipeline) {
  GstBus* bus = gst_element_get_bus(pipeline);
  std::string state;
  auto deadline = std::chrono::steady_clock::now() + wircam::testing::patience(milliseconds(3000));
  while (state.empty() && std::chrono::steady_clock::now() < deadline) {
    GstMessage* m = gst_bus_timed_pop_filtered(bus, 100 * GST_MSECOND, GST_MESSAGE_ELEMENT);
    if (!m) continue;
    const GstStructure* s = gst_message_get_structure(m);
    if (gst_structure_has_name(s, "wirc-vehicle") && gst_structure_has_field(s, "state"))
      state = gst_structure_get_string(s, "state");
    gst_message_unref(m);
  }
  gst_object_unref(bus);
  return state;
}

// A link that logged in before the element listened (another element's, or
// an RCOIP receiver that answered within microseconds) is still announced.
TEST(VehicleLinkElements, WirccontrolJoiningALiveLinkPostsThatItIsLive) {
  auto receiver = sim::startVehicleControl("rcoip", "127.0.0.1", 0, {});
  ASSERT_TRUE(receiver.has_value());
  auto description = "fakesrc is-live=true ! wirccontrol protocol=rcoip host=127.0.0.1 port=" +
                     std::to_string((*receiver)->port()) + " ! fakesink";
  GstElement* first = launch(description);
  gst_element_set_state(first, GST_STATE_PLAYING);
  ASSERT_EQ(firstVehicleState(first), "live");
  GstElement* second = launch(description);
  gst_element_set_state(second, GST_STATE_PLAYING);
  EXPECT_EQ(firstVehicleState(second), "live");
  for (GstElement* pipeline : {first, second}) {
    gst_element_set_state(pipeline, GST_STATE_NULL);
    gst_object_unref(pipeline);
  }
}

}  // namespace
