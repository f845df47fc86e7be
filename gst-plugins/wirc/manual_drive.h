// Driving by hand (wirccontrol's `drive` action, the recorder's drive
// mode): each command goes to the vehicle at once and holds for a short
// time only. When no newer one has come by then, the vehicle goes to
// neutral on the event loop's timer — a dead-man that works whatever the
// pipeline does, even when no frame comes at all.
#pragma once

#include <chrono>
#include <functional>
#include <memory>

#include "common/mutex.h"
#include "link/event_loop.h"
#include "link/vehicle_link.h"

namespace wircam::gst {

class ManualDrive {
 public:
  // Called on the event loop when the dead-man sent neutral.
  explicit ManualDrive(std::function<void()> onLapsed);
  ~ManualDrive();
  ManualDrive(const ManualDrive&) = delete;
  ManualDrive& operator=(const ManualDrive&) = delete;

  // Sends `pulses` through `link` now; `neutral` follows after `hold`
  // unless another command comes first.
  void drive(std::shared_ptr<link::VehicleLink> link, const link::Pulses& pulses,
             const link::Pulses& neutral, std::chrono::milliseconds hold);
  // Neutral now, and the end of driving by hand (the driver left).
  void release();
  // Whether a command by hand holds the vehicle: the follower keeps off.
  bool active();

 private:
  void onDeadline();

  std::function<void()> onLapsed_;
  Mutex mutex_;
  std::shared_ptr<link::VehicleLink> link_ WIRCAM_GUARDED_BY(mutex_);
  link::Pulses neutral_ WIRCAM_GUARDED_BY(mutex_) = link::neutralPulses();
  link::Clock::time_point deadline_ WIRCAM_GUARDED_BY(mutex_);
  link::EventLoop::Id timer_;
};

}  // namespace wircam::gst
