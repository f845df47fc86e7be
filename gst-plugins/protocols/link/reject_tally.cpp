#include "link/reject_tally.h"

namespace wircam::link {

std::optional<InputRejected> RejectTally::summary(Clock::time_point now) {
  if (unreported_.empty() || now - lastSummary_ < kSummaryPeriod) return std::nullopt;
  InputRejected event{0, ""};
  for (const auto& [kind, count] : unreported_) {
    event.count += count;
    event.detail += (event.detail.empty() ? "" : ", ") + std::to_string(count) + " " + kind;
  }
  unreported_.clear();
  lastSummary_ = now;
  return event;
}

}  // namespace wircam::link
