#include "manual_drive.h"

#include "common/mutex.h"

namespace wircam::gst {

struct ManualDrive::Hold {
  std::function<void()> onLapsed;
  Mutex mutex;
  std::shared_ptr<link::VehicleLink> link WIRCAM_GUARDED_BY(mutex);
  link::Pulses neutral WIRCAM_GUARDED_BY(mutex) = link::neutralPulses();
  GstClockID deadline WIRCAM_GUARDED_BY(mutex) = nullptr;  // the latest command's

  // Lets the pending deadline go; the mutex is held.
  void cancelDeadline() WIRCAM_REQUIRES(mutex) {
    if (!deadline) return;
    gst_clock_id_unschedule(deadline);
    gst_clock_id_unref(deadline);
    deadline = nullptr;
  }
};

ManualDrive::ManualDrive(GstElement* element, std::function<void()> onLapsed)
    : element_(element), hold_(std::make_shared<Hold>()) {
  hold_->onLapsed = std::move(onLapsed);
}

ManualDrive::~ManualDrive() {
  release();
  MutexLock lock(hold_->mutex);
  hold_->onLapsed = nullptr;  // a callback already under way does nothing more
}

void ManualDrive::drive(std::shared_ptr<link::VehicleLink> link, const link::Pulses& pulses,
                        const link::Pulses& neutral, std::chrono::milliseconds hold) {
  GstClock* clock = gst_element_get_clock(element_);
  if (!clock) clock = gst_system_clock_obtain();
  auto holdTime = static_cast<GstClockTime>(hold.count()) * GST_MSECOND;
  GstClockID deadline = gst_clock_new_single_shot_id(clock, gst_clock_get_time(clock) + holdTime);
  gst_object_unref(clock);
  {
    MutexLock lock(hold_->mutex);
    hold_->cancelDeadline();
    hold_->link = link;
    hold_->neutral = neutral;
    hold_->deadline = gst_clock_id_ref(deadline);
  }
  link->setCommand(pulses);
  // The callback owns a reference to the hold, so it may outlive this object.
  gst_clock_id_wait_async(deadline, onDeadline, new std::shared_ptr<Hold>(hold_),
                          [](gpointer data) { delete static_cast<std::shared_ptr<Hold>*>(data); });
  gst_clock_id_unref(deadline);
}

void ManualDrive::release() {
  std::shared_ptr<link::VehicleLink> link;
  link::Pulses neutral;
  {
    MutexLock lock(hold_->mutex);
    hold_->cancelDeadline();
    link = std::move(hold_->link);
    neutral = hold_->neutral;
  }
  if (link) link->setCommand(neutral);
}

bool ManualDrive::active() {
  MutexLock lock(hold_->mutex);
  return hold_->link != nullptr;
}

gboolean ManualDrive::onDeadline(GstClock*, GstClockTime, GstClockID id, gpointer data) {
  auto& hold = **static_cast<std::shared_ptr<Hold>*>(data);
  MutexLock lock(hold.mutex);
  // A newer command's deadline replaced this one (its unschedule may come
  // too late to stop the callback): only the latest counts.
  if (id != hold.deadline || !hold.link) return TRUE;
  gst_clock_id_unref(hold.deadline);
  hold.deadline = nullptr;
  auto link = std::move(hold.link);
  link->setCommand(hold.neutral);
  // Under the mutex, so that a destructor cannot take onLapsed away midway.
  if (hold.onLapsed) hold.onLapsed();
  return TRUE;
}

}  // namespace wircam::gst
