#include "pid_controller.h"

#include <algorithm>

namespace wircam::vision {

double PidController::update(double setPoint, double measurement, double dt) {
  double error = setPoint - measurement;
  double derivative = 0;
  if (lastMeasurement_ && dt > 0) derivative = -(measurement - *lastMeasurement_) / dt;
  lastMeasurement_ = measurement;
  if (dt > 0 && gains_.ki != 0) {
    integral_ += error * dt;
    // Anti-windup: the integral term alone stays within the output limits.
    double a = gains_.outputMin / gains_.ki, b = gains_.outputMax / gains_.ki;
    integral_ = std::clamp(integral_, std::min(a, b), std::max(a, b));
  }
  double output = gains_.kp * error + gains_.ki * integral_ + gains_.kd * derivative;
  return std::clamp(output, gains_.outputMin, gains_.outputMax);
}

void PidController::reset() {
  integral_ = 0;
  lastMeasurement_.reset();
}

}  // namespace wircam::vision
