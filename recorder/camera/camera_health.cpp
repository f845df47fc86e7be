#include "camera/camera_health.h"

#include <algorithm>
#include <utility>

namespace wircam::recorder {

const char* toString(CameraState state) {
  switch (state) {
    case CameraState::kConnecting:
      return "connecting";
    case CameraState::kLive:
      return "live";
    case CameraState::kNoVideo:
      return "no-video";
    case CameraState::kOffline:
      return "offline";
  }
  return "connecting";
}

const char* toString(CameraFault fault) {
  switch (fault) {
    case CameraFault::kError:
      return "a pipeline error";
    case CameraFault::kStall:
      return "no video";
    case CameraFault::kLoss:
      return "the device was lost";
  }
  return "a fault";
}

CameraHealth::CameraHealth(Policy policy, Clock::time_point now)
    : policy_(policy), loginTime_(now), startedAt_(now) {}

void CameraHealth::linkUp(Clock::time_point now) {
  if (linkLive_) return;
  linkLive_ = everLive_ = true;
  loginTime_ = now;
  framesSinceLogin_ = false;
  stallReported_ = false;
}

void CameraHealth::linkDown(Clock::time_point) {
  linkLive_ = false;
  noVideo_ = false;
}

void CameraHealth::frame(Clock::time_point now) {
  lastFrame_ = now;
  framesSinceLogin_ = true;
  stallReported_ = false;
  noVideo_ = false;
  // Recording steadily since the last restart: the next fault starts over.
  if (now - startedAt_ >= policy_.healthyAfter) consecutiveFaults_ = 0;
}

bool CameraHealth::stalled(Clock::time_point now) const {
  if (!linkLive_ || restartPending_ || stallReported_) return false;
  Clock::time_point since = loginTime_;
  if (framesSinceLogin_ && lastFrame_) since = std::max(since, *lastFrame_);
  return now - since >= policy_.stallTimeout;
}

CameraHealth::Clock::duration CameraHealth::backoff() const {
  Clock::duration delay = policy_.firstBackoff;
  for (unsigned i = 1; i < consecutiveFaults_ && delay < policy_.maxBackoff; ++i) delay *= 2;
  return std::min(delay, policy_.maxBackoff);
}

CameraHealth::Clock::time_point CameraHealth::fault(CameraFault fault, Clock::time_point now) {
  if (fault == CameraFault::kStall) {
    stallReported_ = true;
    noVideo_ = true;
  }
  // Shown until the next run starts: what the fault says, or (an error)
  // what the camera was.
  if (fault == CameraFault::kStall)
    stateAtFault_ = CameraState::kNoVideo;
  else if (fault == CameraFault::kLoss)
    stateAtFault_ = CameraState::kOffline;
  else
    stateAtFault_ = state(now);
  restartPending_ = true;
  ++consecutiveFaults_;
  return now + backoff();
}

void CameraHealth::replan(Policy policy, Clock::time_point now) {
  if (!restartPending_) stateAtFault_ = state(now);
  policy_ = policy;
  restartPending_ = true;
  replanned_ = true;
}

void CameraHealth::restarted(Clock::time_point now) {
  restartPending_ = false;
  linkLive_ = false;
  startedAt_ = now;
  // New settings: connecting with them (maybe to another device), not a
  // device lost; a fault's restart counts.
  if (std::exchange(replanned_, false))
    everLive_ = false;
  else
    ++restarts_;
}

CameraState CameraHealth::state(Clock::time_point now) const {
  if (restartPending_) return stateAtFault_;
  // A camera restarted for want of video keeps saying so while it logs in
  // again, until a frame comes or the device is lost.
  if (!linkLive_) {
    if (noVideo_) return CameraState::kNoVideo;
    return everLive_ ? CameraState::kOffline : CameraState::kConnecting;
  }
  Clock::time_point since = loginTime_;
  if (framesSinceLogin_ && lastFrame_) since = std::max(since, *lastFrame_);
  bool silent = now - since >= policy_.stallTimeout;
  if (framesSinceLogin_) return silent ? CameraState::kNoVideo : CameraState::kLive;
  return silent || noVideo_ ? CameraState::kNoVideo : CameraState::kConnecting;
}

}  // namespace wircam::recorder
