#include "marvelmind/dashboard_clock.h"

#include <algorithm>

namespace wircam::marvelmind {

namespace {
constexpr uint32_t kHalfRange = 0x80000000u;

double secondsSinceEpoch(DashboardClock::Clock::time_point t) {
  return std::chrono::duration<double>(t.time_since_epoch()).count();
}
}  // namespace

double DashboardClock::seconds(uint32_t timestamp) {
  if (last_ && timestamp < *last_) {
    if (*last_ - timestamp > kHalfRange)
      ++wraps_;  // the counter went round
    else
      samples_.clear(), wraps_ = 0;  // the dashboard restarted
  }
  last_ = timestamp;
  double perWrap = secondsOf(0xFFFFFFFFu, unit_) + secondsOf(1, unit_);
  return static_cast<double>(wraps_) * perWrap + secondsOf(timestamp, unit_);
}

DashboardClock::Clock::time_point DashboardClock::localTime(double dashboardSeconds,
                                                            Clock::time_point received) {
  while (!samples_.empty() && received - samples_.front().received > kWindow) samples_.pop_front();
  samples_.push_back({received, secondsSinceEpoch(received) - dashboardSeconds});
  double offset = std::min_element(samples_.begin(), samples_.end(), [](auto& a, auto& b) {
                    return a.offset < b.offset;
                  })->offset;
  auto local = Clock::time_point(std::chrono::duration_cast<Clock::duration>(
      std::chrono::duration<double>(dashboardSeconds + offset)));
  return std::min(local, received);
}

}  // namespace wircam::marvelmind
