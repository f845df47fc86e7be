// Driving by hand (wirccontrol's `drive` action, the recorder's drive
// mode): each command goes to the vehicle at once and holds for a short
// time only. When no newer one has come by then, the vehicle goes to
// neutral — a dead-man on the pipeline clock (a single-shot clock id), so
// it works whatever the pipeline does, even when no frame comes at all, and
// a test clock drives it in tests.
#pragma once

#include <gst/gst.h>

#include <chrono>
#include <functional>
#include <memory>

#include "link/vehicle_link.h"

namespace wircam::gst {

class ManualDrive {
 public:
  // `element`'s clock times the dead-man (the system clock while it has
  // none); `onLapsed` is called, on the clock's thread, once it sent neutral.
  ManualDrive(GstElement* element, std::function<void()> onLapsed);
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
  struct Hold;  // shared with the pending clock callback
  static gboolean onDeadline(GstClock*, GstClockTime, GstClockID id, gpointer hold);

  GstElement* element_;
  std::shared_ptr<Hold> hold_;
};

}  // namespace wircam::gst
