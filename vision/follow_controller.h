// Visual servoing for a car-like vehicle: an image-based unicycle law. The
// steering follows the target tag's bearing (its horizontal offset from the
// image centre), the speed follows its distance (from the tag's apparent
// size, or its pose) towards a set point. Each axis runs a PID, then a
// deadband and a slew-rate limit, and becomes a pulse width through a
// PulseMap, so every command is inside min..max (and 800..2200).
#pragma once

#include <cstdint>
#include <optional>

#include "pid_controller.h"

namespace wircam::vision {

// Normalised command (−1..1) → pulse width in µs for one channel.
struct PulseMap {
  uint16_t neutral = 1500;
  uint16_t min = 1000;
  uint16_t max = 2000;
  bool reversed = false;
  // Pulses within ± this of neutral are not sent: many ESCs need an offset
  // before they move at all, so the map starts beyond it.
  uint16_t deadband = 0;

  uint16_t toPulse(double command) const;
};

struct FollowConfig {
  double fx = 0;  // focal length in pixels (0: from the horizontal field of view)
  double horizontalFovDeg = 60;
  double tagSize = 0.16;        // m, for the distance from apparent size
  double targetDistance = 1.0;  // m
  PidGains steering{.kp = 2.5, .ki = 0.6, .kd = 0.1, .outputMin = -1, .outputMax = 1};
  PidGains throttle{.kp = 1.2, .ki = 0.4, .kd = 0.0, .outputMin = -0.6, .outputMax = 0.8};
  double steeringDeadbandRad = 0.0;  // no steering for bearings smaller than this
  double distanceDeadband = 0.02;    // m
  double maxSteeringRate = 6.0;      // normalised units per second
  double maxThrottleRate = 3.0;
  PulseMap steeringMap{.neutral = 1500, .min = 1000, .max = 2000};  // 2000 = left
  PulseMap throttleMap{.neutral = 1500, .min = 1200, .max = 1800, .deadband = 50};
};

// One look at the target tag, in the input image's pixels.
struct TargetObservation {
  double centerX = 0;
  double sizePx = 0;  // mean edge length of the tag
  int imageWidth = 0;
  std::optional<double> distance;  // m, from pose when known
};

struct FollowCommand {
  uint16_t steeringPulse;
  uint16_t throttlePulse;
  double bearingRad = 0;  // + = target to the left
  double distance = 0;    // m
  double steering = 0;    // normalised, after limits
  double throttle = 0;
};

class FollowController {
 public:
  explicit FollowController(FollowConfig config);

  // dt: seconds since the previous update.
  FollowCommand update(const TargetObservation& target, double dt);
  // No target: both axes brought to neutral (and the integrators reset).
  FollowCommand neutral();
  const FollowConfig& config() const { return config_; }

 private:
  double slew(double previous, double wanted, double maxRate, double dt) const;

  FollowConfig config_;
  PidController steeringPid_;
  PidController throttlePid_;
  double steering_ = 0;
  double throttle_ = 0;
};

}  // namespace wircam::vision
