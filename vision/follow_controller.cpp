#include "follow_controller.h"

#include <algorithm>
#include <cmath>

namespace wircam::vision {

namespace {
constexpr double kPi = 3.14159265358979323846;
constexpr uint16_t kPulseFloor = 800;  // the WiRC range, whatever the map says
constexpr uint16_t kPulseCeiling = 2200;
}  // namespace

uint16_t PulseMap::toPulse(double command) const {
  command = std::clamp(command, -1.0, 1.0);
  if (reversed) command = -command;
  double pulse = neutral;
  if (command > 0) pulse = neutral + deadband + command * (max - neutral - deadband);
  if (command < 0) pulse = neutral - deadband + command * (neutral - min - deadband);
  if (command == 0) pulse = neutral;
  double low = std::max<double>(min, kPulseFloor), high = std::min<double>(max, kPulseCeiling);
  return static_cast<uint16_t>(std::lround(std::clamp(pulse, low, high)));
}

FollowController::FollowController(FollowConfig config)
    : config_(config), steeringPid_(config.steering), throttlePid_(config.throttle) {}

double FollowController::slew(double previous, double wanted, double maxRate, double dt) const {
  double step = maxRate * std::max(dt, 0.0);
  return std::clamp(wanted, previous - step, previous + step);
}

FollowCommand FollowController::update(const TargetObservation& target, double dt) {
  double fx = config_.fx > 0
                  ? config_.fx
                  : target.imageWidth / 2.0 / std::tan(config_.horizontalFovDeg * kPi / 360.0);
  double centre = target.imageWidth / 2.0 - 0.5;
  // Image x grows to the right; a target on the left is a positive bearing.
  double bearing = std::atan2(centre - target.centerX, fx);
  double distance = target.distance
                        ? *target.distance
                        : (target.sizePx > 0 ? fx * config_.tagSize / target.sizePx : 0);

  double bearingError = std::abs(bearing) < config_.steeringDeadbandRad ? 0 : bearing;
  double distanceError = distance - config_.targetDistance;
  if (std::abs(distanceError) < config_.distanceDeadband) distanceError = 0;

  // The PIDs drive the errors to zero: set point 0, measurement −error.
  double steer = steeringPid_.update(0, -bearingError, dt);
  double drive = throttlePid_.update(0, -distanceError, dt);
  steering_ = slew(steering_, steer, config_.maxSteeringRate, dt);
  throttle_ = slew(throttle_, drive, config_.maxThrottleRate, dt);
  return {config_.steeringMap.toPulse(steering_),
          config_.throttleMap.toPulse(throttle_),
          bearing,
          distance,
          steering_,
          throttle_};
}

FollowCommand FollowController::neutral() {
  steeringPid_.reset();
  throttlePid_.reset();
  steering_ = throttle_ = 0;
  return {config_.steeringMap.neutral, config_.throttleMap.neutral, 0, 0, 0, 0};
}

}  // namespace wircam::vision
