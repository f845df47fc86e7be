#include "marvelmind/dashboard_clock.h"

#include <algorithm>

namespace wircam::marvelmind {

namespace {
constexpr uint32_t kHalfRange = 0x80000000u;

// Longer than any dashboard runs (≈ 31 years): clamped to it, a corrupt
// timestamp cannot overflow the clock's 64-bit ticks.
constexpr double kLongestRunSeconds = 1e9;

DashboardClock::Clock::duration ticksOf(double seconds) {
  return std::chrono::round<DashboardClock::Clock::duration>(
      std::chrono::duration<double>(std::clamp(seconds, 0.0, kLongestRunSeconds)));
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
  Clock::duration dashboard = ticksOf(dashboardSeconds);
  samples_.push_back({received, received.time_since_epoch() - dashboard});
  Clock::duration offset = std::min_element(samples_.begin(), samples_.end(), [](auto& a, auto& b) {
                             return a.offset < b.offset;
                           })->offset;
  return std::min(Clock::time_point(dashboard + offset), received);
}

}  // namespace wircam::marvelmind
