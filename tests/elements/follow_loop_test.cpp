// The closed loop: wirc-sim's follow scene, wircsrc ! tjpegdec !
// apriltagdetect ! wirccontrol, and the car driven by the PCD it sends.
#include <gst/gst.h>
#include <gtest/gtest.h>

#include <thread>

#include "devices/wirc/device.h"
#include "follow_scene.h"
#include "wait_for.h"

namespace {

using namespace wircam;
using std::chrono::milliseconds;
using Clock = std::chrono::steady_clock;
using wircam::testing::waitFor;

// How soon after lost-timeout the car stops is the unit tests' business
// (TargetFollower, CommandPacer: fake clock) and the benchmarks'; these
// end-to-end runs check that it stops, and not too early.
constexpr int kLostTimeoutMs = 500;
constexpr int kFramePeriodMs = 67;

struct Loop {
  std::shared_ptr<sim::FollowScene> scene;
  std::unique_ptr<wirc::Device> device;
  GstElement* pipeline = nullptr;

  explicit Loop(wirc::Impairments impairments = {}) {
    scene = std::move(*sim::FollowScene::create({.path = sim::TargetPath::Circle}));
    auto started =
        wirc::Device::start({.port = 0, .fragmentSize = 1400, .impairments = impairments}, scene);
    EXPECT_TRUE(started.has_value());
    device = std::move(*started);
    auto port = std::to_string(device->port());
    std::string description =
        "wircsrc name=src host=127.0.0.1 port=" + port +
        " ! tjpegdec ! apriltagdetect quad-decimate=1 ! wirccontrol host=127.0.0.1 port=" + port +
        " lost-timeout=" + std::to_string(kLostTimeoutMs) + " ! fakesink";
    pipeline = gst_parse_launch(description.c_str(), nullptr);
    EXPECT_NE(pipeline, nullptr);
    gst_element_set_state(pipeline, GST_STATE_PLAYING);
  }
  ~Loop() {
    gst_element_set_state(pipeline, GST_STATE_NULL);
    gst_object_unref(pipeline);
  }

  // Milliseconds until the car's throttle output is neutral (or -1).
  int millisecondsUntilStopped(milliseconds limit) const {
    auto start = Clock::now();
    while (Clock::now() - start < limit) {
      auto outputs = device->outputs();
      if (outputs.pulses[1] == wirc::kPulseNeutral)
        return static_cast<int>(
            std::chrono::duration_cast<milliseconds>(Clock::now() - start).count());
      std::this_thread::sleep_for(milliseconds(2));
    }
    return -1;
  }
};

TEST(FollowLoop, KeepsTheMovingTargetCentredAtTheSetDistanceWithPacketLoss) {
  Loop loop({.loss = 0.02, .seed = 17});
  // 17 s of the scene's own time measured (255 frames at 15 fps, after its
  // 3 s to settle): the scene's clock, not the test's, says when.
  ASSERT_TRUE(
      waitFor([&] { return loop.scene->summary().measuredTicks >= 255; }, milliseconds(40000)));
  auto summary = loop.scene->summary();
  ASSERT_GT(summary.measuredTicks, 200u);
  EXPECT_LT(summary.meanBearingDeg, 3.0);
  // Within 10 % of the 1 m set point after the first 3 s.
  EXPECT_LT(summary.meanDistanceError, 0.10);
  EXPECT_LT(summary.maxDistanceError, 0.30);
  // Commands leave on change and keepalives fill the pauses: the device's
  // watchdog never fired.
  EXPECT_EQ(loop.device->stats().failsafeEntries, 0u);
}

TEST(FollowLoop, StopsTheCarWhenTheTagIsHidden) {
  Loop loop;
  // Following: the throttle above neutral.
  ASSERT_TRUE(waitFor([&] { return loop.device->outputs().pulses[1] != wirc::kPulseNeutral; },
                      milliseconds(10000)));
  loop.scene->setTargetHidden(true);
  int stoppedAfter = loop.millisecondsUntilStopped(milliseconds(3000));
  ASSERT_GE(stoppedAfter, 0) << "the car never stopped";
  // The last sighting is at most one frame before the tag was hidden.
  EXPECT_GE(stoppedAfter, kLostTimeoutMs - kFramePeriodMs - 30);  // not before lost-timeout
}

TEST(FollowLoop, StopsTheCarWhenThePipelineStalls) {
  Loop loop;
  ASSERT_TRUE(waitFor([&] { return loop.device->outputs().pulses[1] != wirc::kPulseNeutral; },
                      milliseconds(10000)));
  GstElement* src = gst_bin_get_by_name(GST_BIN(loop.pipeline), "src");
  GstPad* pad = gst_element_get_static_pad(src, "src");
  // The source's next buffer blocks its streaming thread until the probe
  // goes, as a stalled pipeline would.
  gulong probe = gst_pad_add_probe(
      pad, GST_PAD_PROBE_TYPE_BLOCK_DOWNSTREAM,
      [](GstPad*, GstPadProbeInfo*, gpointer) { return GST_PAD_PROBE_OK; }, nullptr, nullptr);
  int stoppedAfter = loop.millisecondsUntilStopped(milliseconds(2500));
  ASSERT_GE(stoppedAfter, 0) << "the car never stopped";
  EXPECT_FALSE(loop.device->outputs().failsafe);  // stopped by neutral PCD, link kept
  gst_pad_remove_probe(pad, probe);
  gst_object_unref(pad);
  gst_object_unref(src);
}

}  // namespace
