#include "link/alarm.h"

#include <sys/epoll.h>
#include <sys/timerfd.h>
#include <unistd.h>

#include <algorithm>

namespace wircam::link {

Alarm::Alarm(EventLoop& loop, EventLoop::Callback onAlarm)
    : loop_(loop),
      timer_(timerfd_create(CLOCK_MONOTONIC, TFD_CLOEXEC | TFD_NONBLOCK)),
      onAlarm_(std::move(onAlarm)) {
  watch_ = loop_.watch(timer_.get(), EPOLLIN, [this](uint32_t) { onReadable(); });
}

Alarm::~Alarm() { stop(); }

void Alarm::stop() {
  if (watch_ == 0) return;
  loop_.remove(watch_);
  watch_ = 0;
}

Clock::time_point Alarm::dueTime(Clock::time_point earliest, Clock::time_point latest) {
  using std::chrono::nanoseconds;
  auto grid = std::chrono::duration_cast<nanoseconds>(EventLoop::kCoalesce).count();
  auto from = std::chrono::duration_cast<nanoseconds>(earliest.time_since_epoch()).count();
  auto tick = Clock::time_point(nanoseconds((from + grid - 1) / grid * grid));
  return std::min(tick, std::max(earliest, latest));
}

void Alarm::set(Clock::time_point earliest, Clock::time_point latest) {
  // steady_clock is CLOCK_MONOTONIC. At least 1 ns: zero would disarm,
  // and a time passed goes off at once.
  auto ns = std::max<int64_t>(1, std::chrono::duration_cast<std::chrono::nanoseconds>(
                                     dueTime(earliest, latest).time_since_epoch())
                                     .count());
  itimerspec due{.it_interval = {},
                 .it_value = {.tv_sec = ns / 1000000000, .tv_nsec = ns % 1000000000}};
  timerfd_settime(timer_.get(), TFD_TIMER_ABSTIME, &due, nullptr);
}

void Alarm::onReadable() {
  uint64_t expirations = 0;
  // Nothing to read: it was moved after it went off and before the loop
  // came to it, so it is not due.
  if (read(timer_.get(), &expirations, sizeof expirations) <= 0) return;
  onAlarm_();
}

}  // namespace wircam::link
