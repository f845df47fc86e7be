// Malformed input from a vehicle, counted by kind and summed up at most once
// a second: a hostile or broken peer costs a counter, not a message per
// datagram.
#pragma once

#include <cstdint>
#include <map>
#include <optional>
#include <string>

#include "link/event_loop.h"
#include "link/vehicle_link.h"

namespace wircam::link {

class RejectTally {
 public:
  static constexpr std::chrono::milliseconds kSummaryPeriod{1000};

  void count(const std::string& kind) { ++unreported_[kind], ++total_; }
  uint64_t total() const { return total_; }
  // The summary of what came since the last one, once a period has passed.
  std::optional<InputRejected> summary(Clock::time_point now);

 private:
  std::map<std::string, uint64_t> unreported_;
  uint64_t total_ = 0;
  Clock::time_point lastSummary_{};
};

}  // namespace wircam::link
