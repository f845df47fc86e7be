#include "manual_drive.h"

namespace wircam::gst {

ManualDrive::ManualDrive(std::function<void()> onLapsed)
    : onLapsed_(std::move(onLapsed)),
      timer_(link::EventLoop::shared().addTimer([this] { onDeadline(); })) {}

ManualDrive::~ManualDrive() {
  link::EventLoop::shared().remove(timer_);
  release();
}

void ManualDrive::drive(std::shared_ptr<link::VehicleLink> link, const link::Pulses& pulses,
                        const link::Pulses& neutral, std::chrono::milliseconds hold) {
  auto deadline = link::Clock::now() + hold;
  {
    MutexLock lock(mutex_);
    link_ = link;
    neutral_ = neutral;
    deadline_ = deadline;
  }
  link->setCommand(pulses);
  link::EventLoop::shared().arm(timer_, deadline);
}

void ManualDrive::release() {
  std::shared_ptr<link::VehicleLink> link;
  link::Pulses neutral;
  {
    MutexLock lock(mutex_);
    link = std::move(link_);
    neutral = neutral_;
  }
  if (link) link->setCommand(neutral);
}

bool ManualDrive::active() {
  MutexLock lock(mutex_);
  return link_ != nullptr;
}

void ManualDrive::onDeadline() {
  std::shared_ptr<link::VehicleLink> link;
  link::Pulses neutral;
  {
    MutexLock lock(mutex_);
    if (!link_) return;
    // Timers may fire a little early (the loop coalesces wake-ups), and a
    // newer command may have moved the deadline: only a passed one counts.
    if (link::Clock::now() < deadline_) {
      link::EventLoop::shared().arm(timer_, deadline_);
      return;
    }
    link = std::move(link_);
    neutral = neutral_;
  }
  link->setCommand(neutral);
  if (onLapsed_) onLapsed_();
}

}  // namespace wircam::gst
