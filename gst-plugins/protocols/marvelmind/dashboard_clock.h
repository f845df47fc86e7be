// The dashboard's clock seen from here: its 32-bit timestamps unwrapped into
// seconds, and mapped onto this machine's steady clock. A reply leaves the
// dashboard some time after the measurement it carries (it answers each poll
// with its latest), so the time of a measurement here is its dashboard time
// plus the smallest offset (arrival − dashboard time) seen lately: the reply
// that came quickest shows the two clocks' true offset best.
#pragma once

#include <chrono>
#include <cstdint>
#include <deque>
#include <optional>

#include "marvelmind/marvelmind_messages.h"

namespace wircam::marvelmind {

class DashboardClock {
 public:
  using Clock = std::chrono::steady_clock;
  // Offsets older than this are forgotten, so the two clocks may drift.
  static constexpr std::chrono::seconds kWindow{10};

  explicit DashboardClock(TimestampUnit unit) : unit_(unit) {}

  // Seconds since the dashboard started. A step back (other than the
  // counter's wrap) is a restarted dashboard: the offsets start over.
  double seconds(uint32_t timestamp);
  // When the measurement stamped `dashboardSeconds` was made, on this clock;
  // never later than `received`.
  Clock::time_point localTime(double dashboardSeconds, Clock::time_point received);

 private:
  struct Sample {
    Clock::time_point received;
    // received − dashboard time, in the clock's own ticks: a measurement
    // whose own offset is the smallest lands exactly on its arrival.
    Clock::duration offset;
  };
  TimestampUnit unit_;
  std::optional<uint32_t> last_;
  uint64_t wraps_ = 0;
  std::deque<Sample> samples_;  // by arrival; the smallest offset is wanted
};

}  // namespace wircam::marvelmind
