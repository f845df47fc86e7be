// What a recorder run does on time, apart from each camera's own deadlines:
// end at --duration, show the status and guard the disk, tick the cameras,
// publish to MQTT and Foxglove, Home Assistant's snapshots, retention, and
// the stop's backstop. Time is passed in, as the camera's machine takes it:
// the schedule is tested without a clock or a loop, and the supervisor's one
// GLib timer is armed to next() and asks due() when it fires.
#pragma once

#include <chrono>
#include <optional>
#include <vector>

namespace wircam::recorder {

enum class RunJob {
  End,             // --duration is over
  Status,          // the status line, the disk guard
  CameraTick,      // each camera's stall and restart checks, Foxglove's poses
  FleetStatus,     // MQTT's status (published on change, at least this often)
  FoxgloveStatus,  // each camera's /STREAM/telemetry
  Snapshots,       // --mqtt-discovery's camera entity
  Retention,       // --max-age, whether or not a segment closes
  StopBackstop,    // a stop that has not finished by now quits anyway
};

// How often each job runs; a job without a period never does.
struct RunPeriods {
  using ms = std::chrono::milliseconds;
  std::optional<ms> duration;
  ms status{1000};
  ms cameraTick{250};
  std::optional<ms> fleetStatus;
  std::optional<ms> foxgloveStatus;
  std::optional<ms> snapshots;
  ms retention{60000};
};

class RunSchedule {
 public:
  using Clock = std::chrono::steady_clock;

  RunSchedule(const RunPeriods& periods, Clock::time_point start);

  // The jobs due at `now`, in RunJob's order, each once however late: a
  // periodic job's next turn stays on its grid (start + k·period), the turns
  // a busy machine missed skipped, not run in a burst.
  std::vector<RunJob> due(Clock::time_point now);
  // When the earliest job is due.
  Clock::time_point next() const;
  // The run is stopping: the backstop, once, `bound` from `now`. The other
  // jobs go on (the status, the cameras' ticks) while the files finish.
  void stopping(Clock::time_point now, std::chrono::milliseconds bound);

 private:
  struct Turn {
    RunJob job;
    Clock::time_point at;
    std::optional<Clock::duration> period;  // none: once
  };
  std::vector<Turn> turns_;
};

}  // namespace wircam::recorder
