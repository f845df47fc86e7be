// A PID controller for one axis: derivative on the measurement (no kick when
// the set point jumps), output limits, and anti-windup by clamping the
// integral so that it alone can never push the output past its limits.
#pragma once

#include <optional>

namespace wircam::vision {

struct PidGains {
  double kp = 0;
  double ki = 0;
  double kd = 0;
  double outputMin = -1;
  double outputMax = 1;
};

class PidController {
 public:
  explicit PidController(PidGains gains) : gains_(gains) {}

  // error = set point − measurement; dt in seconds (> 0).
  double update(double setPoint, double measurement, double dt);
  void reset();
  const PidGains& gains() const { return gains_; }

 private:
  PidGains gains_;
  double integral_ = 0;
  std::optional<double> lastMeasurement_;
};

}  // namespace wircam::vision
