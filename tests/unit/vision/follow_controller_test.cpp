#include "follow_controller.h"

#include <gtest/gtest.h>

#include <cmath>

namespace wircam::vision {
namespace {

TEST(PidController, ProportionalActsOnTheErrorAndClampsTheOutput) {
  PidController pid({.kp = 2, .outputMin = -1, .outputMax = 1});
  EXPECT_DOUBLE_EQ(pid.update(0.25, 0, 0.1), 0.5);
  EXPECT_DOUBLE_EQ(pid.update(10, 0, 0.1), 1);
  EXPECT_DOUBLE_EQ(pid.update(-10, 0, 0.1), -1);
}

TEST(PidController, IntegralRemovesASteadyErrorWithoutWindingUp) {
  PidController pid({.kp = 0, .ki = 1, .outputMin = -1, .outputMax = 1});
  for (int i = 0; i < 1000; ++i) pid.update(5, 0, 0.1);  // saturated for 100 s
  // One step the other way must already move the output off the limit.
  EXPECT_LT(pid.update(-5, 0, 0.1), 1);
}

TEST(PidController, DerivativeActsOnTheMeasurementNotTheSetPoint) {
  PidController pid({.kd = 1, .outputMin = -10, .outputMax = 10});
  pid.update(0, 0, 0.1);
  EXPECT_DOUBLE_EQ(pid.update(5, 0, 0.1), 0);    // set point jump: no kick
  EXPECT_DOUBLE_EQ(pid.update(5, 1, 0.1), -10);  // measurement moved up fast
}

TEST(PulseMap, StaysWithinItsLimitsAndTheWircRange) {
  PulseMap map{.neutral = 1500, .min = 600, .max = 2500};
  EXPECT_EQ(map.toPulse(0), 1500);
  EXPECT_EQ(map.toPulse(5), 2200);
  EXPECT_EQ(map.toPulse(-5), 800);
  PulseMap reversed{.neutral = 1500, .min = 1000, .max = 2000, .reversed = true};
  EXPECT_EQ(reversed.toPulse(1), 1000);
  PulseMap esc{.neutral = 1500, .min = 1200, .max = 1800, .deadband = 50};
  EXPECT_EQ(esc.toPulse(0.001), 1550);
  EXPECT_EQ(esc.toPulse(-1), 1200);
}

TEST(FollowController, SteersTowardsATagOnTheLeftAndDrivesWhenFar) {
  FollowController control({});
  // A tag left of centre, small (far): steer left (> 1500), drive forward.
  FollowCommand command{};
  for (int i = 0; i < 10; ++i)
    command = control.update({.centerX = 100, .sizePx = 20, .imageWidth = 352}, 0.066);
  EXPECT_GT(command.bearingRad, 0);
  EXPECT_GT(command.steeringPulse, 1500);
  EXPECT_GT(command.throttlePulse, 1500);
  EXPECT_GT(command.distance, 2);
}

TEST(FollowController, BacksOffWhenTooCloseAndSlewsGradually) {
  FollowController control({});
  auto first = control.update({.centerX = 175.5, .sizePx = 200, .imageWidth = 352}, 0.05);
  EXPECT_LT(first.throttlePulse, 1500);
  EXPECT_LE(std::abs(first.throttle), 3.0 * 0.05 + 1e-9);  // slew limited
  EXPECT_EQ(control.neutral().throttlePulse, 1500);
}

}  // namespace
}  // namespace wircam::vision
