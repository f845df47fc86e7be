#include "app/run_schedule.h"

#include <algorithm>

namespace wircam::recorder {

RunSchedule::RunSchedule(const RunPeriods& periods, Clock::time_point start) {
  auto every = [&](RunJob job, std::optional<RunPeriods::ms> period) {
    if (!period) return;
    // A zero period would be due at every look: at least a millisecond.
    auto at_least = std::max(*period, RunPeriods::ms(1));
    turns_.push_back({job, start + at_least, at_least});
  };
  if (periods.duration) turns_.push_back({RunJob::End, start + *periods.duration, std::nullopt});
  every(RunJob::Status, periods.status);
  every(RunJob::CameraTick, periods.cameraTick);
  every(RunJob::FleetStatus, periods.fleetStatus);
  every(RunJob::FoxgloveStatus, periods.foxgloveStatus);
  every(RunJob::Snapshots, periods.snapshots);
  every(RunJob::Retention, periods.retention);
}

std::vector<RunJob> RunSchedule::due(Clock::time_point now) {
  std::vector<RunJob> jobs;
  for (auto& turn : turns_) {
    if (turn.at > now) continue;
    jobs.push_back(turn.job);
    if (turn.period)
      turn.at += *turn.period * ((now - turn.at) / *turn.period + 1);  // the next turn after now
  }
  std::erase_if(turns_, [&](const Turn& turn) { return !turn.period && turn.at <= now; });
  std::sort(jobs.begin(), jobs.end());
  return jobs;
}

RunSchedule::Clock::time_point RunSchedule::next() const {
  auto earliest = Clock::time_point::max();
  for (const auto& turn : turns_) earliest = std::min(earliest, turn.at);
  return earliest;
}

void RunSchedule::stopping(Clock::time_point now, std::chrono::milliseconds bound) {
  bool armed = std::any_of(turns_.begin(), turns_.end(),
                           [](const Turn& turn) { return turn.job == RunJob::StopBackstop; });
  if (!armed) turns_.push_back({RunJob::StopBackstop, now + bound, std::nullopt});
}

}  // namespace wircam::recorder
