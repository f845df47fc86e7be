// What the supervisor knows of one camera, and when its pipeline is to be
// started again. GStreamer-free, with time passed in, so that its policy is
// tested without a clock.
//
// The state is what /api/cameras, MQTT and the events say, word for word:
//   connecting  not logged in yet (or logged in, its first frame not due yet)
//   live        logged in, frames arriving
//   no-video    logged in, but no frame for the stall timeout
//   offline     was live, and the link is lost
// A fault (a pipeline error, a stall, a loss with a file open) has the
// pipeline torn down and started again after a backoff: 0.5 s, doubling to
// 30 s, back to 0.5 s once a restarted camera has recorded for 10 s.
#pragma once

#include <chrono>
#include <optional>

namespace wircam::recorder {

enum class CameraState { kConnecting, kLive, kNoVideo, kOffline };
const char* toString(CameraState state);

enum class CameraFault { kError, kStall, kLoss };
const char* toString(CameraFault fault);

class CameraHealth {
 public:
  using Clock = std::chrono::steady_clock;
  struct Policy {
    Clock::duration stallTimeout = std::chrono::seconds(5);
    Clock::duration firstBackoff = std::chrono::milliseconds(500);
    Clock::duration maxBackoff = std::chrono::seconds(30);
    Clock::duration healthyAfter = std::chrono::seconds(10);
    bool operator==(const Policy&) const = default;
  };

  explicit CameraHealth(Policy policy, Clock::time_point now);

  void linkUp(Clock::time_point now);
  void linkDown(Clock::time_point now);
  void frame(Clock::time_point now);
  // Logged in, and no frame for the stall timeout: once per link-up (a
  // stall is a fault only once, until a frame or a new login).
  bool stalled(Clock::time_point now) const;
  // The pipeline is to go: when to start the next one.
  Clock::time_point fault(CameraFault fault, Clock::time_point now);
  // New settings: the pipeline is to go and the next one start with them,
  // at once (not a fault: no backoff, not counted as a restart).
  void replan(Policy policy, Clock::time_point now);
  void setPolicy(Policy policy) { policy_ = policy; }
  // The next pipeline started (its link not up yet).
  void restarted(Clock::time_point now);

  CameraState state(Clock::time_point now) const;
  unsigned restarts() const { return restarts_; }
  const Policy& policy() const { return policy_; }
  bool restartPending() const { return restartPending_; }
  bool replanned() const { return replanned_; }

 private:
  Clock::duration backoff() const;

  Policy policy_;
  bool linkLive_ = false;
  bool everLive_ = false;
  std::optional<Clock::time_point> lastFrame_;
  Clock::time_point loginTime_;
  bool framesSinceLogin_ = false;
  bool stallReported_ = false;
  bool noVideo_ = false;  // the last fault was a stall, and no frame came since
  bool restartPending_ = false;
  bool replanned_ = false;  // the pending restart is new settings', not a fault's
  CameraState stateAtFault_ = CameraState::kConnecting;
  unsigned consecutiveFaults_ = 0;
  unsigned restarts_ = 0;
  Clock::time_point startedAt_;
};

}  // namespace wircam::recorder
