// A camera's lifecycle as a machine that does no I/O, as LoginMachine is for
// the link: events and `now` in; what to do (end the file, tear the
// pipeline down, build the next one, publish the state, say it has ended)
// and the next deadline out. Camera is its GLib driver: it owns the
// pipeline, its bus and the one timer, and does what the actions say.
//
//   running ──fault, file open──► finishing ──EOS / deadline / error──► restarting
//      │  └──fault, no file / error / EOS of itself───────────────────────►  │
//      │                                                                     │
//      │◄────────────── started ◄── (build when due; failed: backoff) ◄──────┘
//      └──stop, file open──► stopping ──EOS / deadline / error──► ended
//   (stop with no file, stop while restarting, halt, a full disk: ended)
//   New settings (replan) go the fault's way with no backoff: finishing,
//   then restarting, built at once.
//
// The words users see (connecting, live, no-video, offline) are
// CameraHealth's; the phase is the lifecycle's own.
#pragma once

#include <chrono>
#include <optional>
#include <string>
#include <vector>

#include "camera/camera_health.h"

namespace wircam::recorder {

enum class CameraPhase { kRunning, kFinishing, kRestarting, kStopping, kEnded };
const char* toString(CameraPhase phase);

struct CameraAction {
  enum class Kind {
    kEndFile,       // end the open file (EOS into the muxer)
    kTearDown,      // the pipeline to NULL and gone, its files indexed as they are
    kBuild,         // build and play the next pipeline; say built() or buildFailed()
    kPublishState,  // the state (health().state) changed: log and tell
    kEnded,         // stopped for good
    kLog,           // `text`, about this camera
  };
  Kind kind;
  // kEndFile: the recording's end (what telemetry waits goes into this
  // file), not a restart's (it goes into the next run's first file).
  bool forGood = false;
  std::string text;
  bool operator==(const CameraAction&) const = default;
};
using CameraActions = std::vector<CameraAction>;

class CameraMachine {
 public:
  using Clock = CameraHealth::Clock;
  // How long a stop or a fault waits for the open file to be finished.
  static constexpr std::chrono::milliseconds kFinishTime{2500};

  CameraMachine(CameraHealth::Policy policy, Clock::time_point now);

  // The link: logged in, or lost (`fileOpen`: a file of this run holds a
  // frame, which a loss then ends at its last frame).
  CameraActions linkUp(Clock::time_point now);
  CameraActions linkLost(bool fileOpen, Clock::time_point now);
  // A frame reached the files since the last event.
  CameraActions frame(Clock::time_point now);
  // The stall check and the deadlines (a finish cut off, a restart due):
  // called on every tick and when the deadline's timer fires.
  CameraActions tick(bool fileOpen, Clock::time_point now);
  // An error on the bus (the driver has said what it was).
  CameraActions pipelineError(Clock::time_point now);
  // A write failed for want of space: this camera stops at once.
  CameraActions diskFull(Clock::time_point now);
  CameraActions endOfStream(Clock::time_point now);
  // What became of a kBuild.
  CameraActions built(Clock::time_point now);
  CameraActions buildFailed(const std::string& why, Clock::time_point now);
  // New settings: the open file finished (bounded by kFinishTime), then a
  // pipeline built with them at once; the settings' stall timeout from now.
  CameraActions replan(CameraHealth::Policy policy, bool fileOpen, Clock::time_point now);
  // Finish the open file (bounded by kFinishTime) and end; halt: end now.
  CameraActions stop(bool fileOpen, Clock::time_point now);
  CameraActions halt(Clock::time_point now);

  // When tick() must be called next, if anything is due.
  std::optional<Clock::time_point> nextDeadline() const;
  CameraPhase phase() const { return phase_; }
  const CameraHealth& health() const { return health_; }
  // Whether telemetry written now belongs to the next run's first file (a
  // restart's finish is under way).
  bool betweenRuns() const { return phase_ == CameraPhase::kFinishing; }

 private:
  void fault(CameraFault fault, const std::string& why, bool fileOpen, Clock::time_point now,
             CameraActions& actions);
  // Tear down, then build again when the fault's backoff is over.
  void restartLater(Clock::time_point now, CameraActions& actions);
  // Tear down (if there is a pipeline) and end for good.
  void end(CameraActions& actions);
  // A finish is over (its EOS, its deadline, an error): the end, or the restart.
  void finished(Clock::time_point now, CameraActions& actions);
  // Appends kPublishState when the state changed since it was last said.
  CameraActions published(CameraActions actions, Clock::time_point now);
  static std::string millisecondsUntil(Clock::time_point when, Clock::time_point now);

  CameraHealth health_;
  CameraPhase phase_ = CameraPhase::kRunning;
  Clock::time_point deadline_{};   // finishing, stopping: the cut-off; restarting: the build
  Clock::time_point restartAt_{};  // finishing: when the next run is due
  CameraState said_ = CameraState::kConnecting;
};

}  // namespace wircam::recorder
