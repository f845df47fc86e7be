// The closed loop with the cousin protocols: the follow scene's camera on
// WiRC MJPEG, and its car steered by an RCOIP receiver or a BTEMP robot
// that wirccontrol protocol=rcoip|btemp commands over real sockets.
#include <gst/gst.h>
#include <gtest/gtest.h>

#include <thread>

#include "devices/wirc/device.h"
#include "follow_scene.h"
#include "vehicle_control.h"
#include "wait_for.h"

namespace {

using namespace wircam;
using std::chrono::milliseconds;
using Clock = std::chrono::steady_clock;
using wircam::testing::waitFor;

constexpr int kLostTimeoutMs = 500;

struct CousinLoop {
  std::shared_ptr<sim::FollowScene> scene;
  std::unique_ptr<sim::VehicleControl> control;
  std::unique_ptr<wirc::Device> device;
  GstElement* pipeline = nullptr;

  explicit CousinLoop(const std::string& protocol) {
    scene = std::move(*sim::FollowScene::create({.path = sim::TargetPath::Circle}));
    auto started = sim::startVehicleControl(protocol, "127.0.0.1", 0, {});
    EXPECT_TRUE(started.has_value());
    control = std::move(*started);
    auto* car = control.get();
    auto device_ = wirc::Device::start(
        {.port = 0,
         .fragmentSize = 1400,
         .carControl = [car](wirc::DeviceClock::time_point now) { return car->outputs(now); }},
        scene);
    EXPECT_TRUE(device_.has_value());
    device = std::move(*device_);
    std::string description =
        "wircsrc host=127.0.0.1 port=" + std::to_string(device->port()) +
        " ! tjpegdec ! apriltagdetect quad-decimate=1 ! wirccontrol name=control protocol=" +
        protocol + " host=127.0.0.1 port=" + std::to_string(control->port()) +
        " lost-timeout=" + std::to_string(kLostTimeoutMs) + " ! fakesink";
    pipeline = gst_parse_launch(description.c_str(), nullptr);
    EXPECT_NE(pipeline, nullptr);
    gst_element_set_state(pipeline, GST_STATE_PLAYING);
  }
  ~CousinLoop() {
    gst_element_set_state(pipeline, GST_STATE_NULL);
    gst_object_unref(pipeline);
    device->stop();
  }

  wirc::ChannelOutputs car() const { return control->outputs(Clock::now()); }
};

class CousinFollowLoop : public ::testing::TestWithParam<const char*> {};

TEST_P(CousinFollowLoop, KeepsTheMovingTargetCentredAtTheSetDistance) {
  CousinLoop loop(GetParam());
  // 9 s of the scene's own time measured (135 frames at 15 fps, after its
  // 3 s to settle).
  ASSERT_TRUE(
      waitFor([&] { return loop.scene->summary().measuredTicks >= 135; }, milliseconds(30000)));
  auto summary = loop.scene->summary();
  ASSERT_GT(summary.measuredTicks, 100u);
  // The same range as the WiRC loop (follow_loop_test).
  EXPECT_LT(summary.meanBearingDeg, 3.0);
  EXPECT_LT(summary.meanDistanceError, 0.10);
  EXPECT_LT(summary.maxDistanceError, 0.30);
  EXPECT_FALSE(loop.car().failsafe) << "the receiver's watchdog fired while following";
}

TEST_P(CousinFollowLoop, StopsTheCarWhenTheTagIsHiddenAndFailsSafeWhenTheControllerLeaves) {
  CousinLoop loop(GetParam());
  // Following: commands arriving (no failsafe) with the throttle above
  // neutral (beyond the byte map's 6 µs step).
  ASSERT_TRUE(waitFor(
      [&] {
        auto car = loop.car();
        return !car.failsafe && car.pulses[1] > wirc::kPulseNeutral + 6;
      },
      milliseconds(10000)));
  loop.scene->setTargetHidden(true);
  auto deadline = Clock::now() + milliseconds(3000);
  // The byte map carries 1500 µs as 128 (1503 µs back): neutral within a step.
  while (std::abs(loop.car().pulses[1] - wirc::kPulseNeutral) > 6 && Clock::now() < deadline)
    std::this_thread::sleep_for(milliseconds(5));
  EXPECT_LE(std::abs(loop.car().pulses[1] - wirc::kPulseNeutral), 6) << "the car never stopped";

  // The pipeline goes: the vehicle fails safe on its own after its fail
  // interval (2 s RCOIP, 1 s here for BTEMP), seen through a later clock.
  gst_element_set_state(loop.pipeline, GST_STATE_NULL);
  EXPECT_TRUE(loop.control->outputs(Clock::now() + milliseconds(2100)).failsafe);
}

INSTANTIATE_TEST_SUITE_P(Protocols, CousinFollowLoop, ::testing::Values("rcoip", "btemp"));

}  // namespace
