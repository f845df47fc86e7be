#include "camera/camera_machine.h"

namespace wircam::recorder {

namespace {
using Kind = CameraAction::Kind;
CameraAction action(Kind kind) { return {kind, false, ""}; }
CameraAction logged(std::string text) { return {Kind::kLog, false, std::move(text)}; }
}  // namespace

const char* toString(CameraPhase phase) {
  switch (phase) {
    case CameraPhase::kRunning:
      return "running";
    case CameraPhase::kFinishing:
      return "finishing";
    case CameraPhase::kRestarting:
      return "restarting";
    case CameraPhase::kStopping:
      return "stopping";
    case CameraPhase::kEnded:
      return "ended";
  }
  return "running";
}

CameraMachine::CameraMachine(CameraHealth::Policy policy, Clock::time_point now)
    : health_(policy, now), said_(health_.state(now)) {}

std::string CameraMachine::millisecondsUntil(Clock::time_point when, Clock::time_point now) {
  auto ms = std::chrono::duration_cast<std::chrono::milliseconds>(when - now).count();
  return std::to_string(std::max<int64_t>(ms, 0)) + " ms";
}

CameraActions CameraMachine::published(CameraActions actions, Clock::time_point now) {
  CameraState state = health_.state(now);
  if (state != said_ && phase_ != CameraPhase::kEnded) {
    said_ = state;
    actions.push_back(action(Kind::kPublishState));
  }
  return actions;
}

void CameraMachine::restartLater(Clock::time_point now, CameraActions& actions) {
  actions.push_back(action(Kind::kTearDown));
  if (phase_ == CameraPhase::kFinishing) deadline_ = restartAt_;  // the fault's backoff
  phase_ = CameraPhase::kRestarting;
  // A pipeline that ended by itself (no fault said so) failed too.
  if (!health_.restartPending()) deadline_ = health_.fault(CameraFault::kError, now);
}

void CameraMachine::finished(Clock::time_point now, CameraActions& actions) {
  if (phase_ == CameraPhase::kStopping)
    end(actions);
  else
    restartLater(now, actions);
}

void CameraMachine::end(CameraActions& actions) {
  // A pipeline there is goes first; while restarting there is none.
  if (phase_ != CameraPhase::kRestarting) actions.push_back(action(Kind::kTearDown));
  phase_ = CameraPhase::kEnded;
  actions.push_back(action(Kind::kEnded));
}

void CameraMachine::fault(CameraFault fault, const std::string& why, bool fileOpen,
                          Clock::time_point now, CameraActions& actions) {
  if (phase_ != CameraPhase::kRunning) return;
  deadline_ = health_.fault(fault, now);
  actions.push_back(logged(why + ": closing its file and starting its pipeline again in " +
                           millisecondsUntil(deadline_, now)));
  if (!fileOpen) {
    // No file to finish, and no EOS would pass a camera that never sent a frame.
    actions.push_back(action(Kind::kTearDown));
    phase_ = CameraPhase::kRestarting;
    return;
  }
  actions.push_back({Kind::kEndFile, false, ""});
  phase_ = CameraPhase::kFinishing;
  restartAt_ = deadline_;
  deadline_ = now + kFinishTime;
}

CameraActions CameraMachine::linkUp(Clock::time_point now) {
  health_.linkUp(now);
  return published({}, now);
}

CameraActions CameraMachine::linkLost(bool fileOpen, Clock::time_point now) {
  health_.linkDown(now);
  CameraActions actions;
  // Lost with a file open: the file ends at its last frame now, not when
  // frames come back; the next one starts with the first frame back.
  if (fileOpen) fault(CameraFault::kLoss, "the device was lost", true, now, actions);
  return published(std::move(actions), now);
}

CameraActions CameraMachine::frame(Clock::time_point now) {
  health_.frame(now);
  return published({}, now);
}

CameraActions CameraMachine::tick(bool fileOpen, Clock::time_point now) {
  CameraActions actions;
  switch (phase_) {
    case CameraPhase::kRunning:
      if (health_.stalled(now))
        fault(CameraFault::kStall,
              "no frame for " +
                  std::to_string(std::chrono::duration_cast<std::chrono::milliseconds>(
                                     health_.policy().stallTimeout)
                                     .count()) +
                  " ms while logged in",
              fileOpen, now, actions);
      break;
    case CameraPhase::kFinishing:
    case CameraPhase::kStopping:
      if (now < deadline_) break;
      actions.push_back(logged("cut off after " + std::to_string(kFinishTime.count()) +
                               " ms (its last file is indexed as it is)"));
      finished(now, actions);
      break;
    case CameraPhase::kRestarting:
      if (now >= deadline_) actions.push_back(action(Kind::kBuild));
      break;
    case CameraPhase::kEnded:
      break;
  }
  return published(std::move(actions), now);
}

CameraActions CameraMachine::pipelineError(Clock::time_point now) {
  CameraActions actions;
  switch (phase_) {
    case CameraPhase::kRunning:
      // An error ends this run at once: EOS would not pass.
      deadline_ = health_.fault(CameraFault::kError, now);
      actions.push_back(logged("restarting its pipeline after the error above in " +
                               millisecondsUntil(deadline_, now) +
                               "; the other cameras record on"));
      restartLater(now, actions);
      break;
    case CameraPhase::kFinishing:
    case CameraPhase::kStopping:
      finished(now, actions);  // what the file holds is what it holds
      break;
    case CameraPhase::kRestarting:
    case CameraPhase::kEnded:
      break;
  }
  return published(std::move(actions), now);
}

CameraActions CameraMachine::diskFull(Clock::time_point now) {
  // This camera's file cannot be finished; the others may still be.
  return halt(now);
}

CameraActions CameraMachine::endOfStream(Clock::time_point now) {
  CameraActions actions;
  switch (phase_) {
    case CameraPhase::kRunning:  // ended by itself
      restartLater(now, actions);
      break;
    case CameraPhase::kFinishing:
    case CameraPhase::kStopping:
      finished(now, actions);
      break;
    case CameraPhase::kRestarting:
    case CameraPhase::kEnded:
      break;
  }
  return published(std::move(actions), now);
}

CameraActions CameraMachine::built(Clock::time_point now) {
  if (phase_ != CameraPhase::kRestarting) return {};
  bool replanned = health_.replanned();
  health_.restarted(now);
  phase_ = CameraPhase::kRunning;
  return published({logged(replanned ? "pipeline started with the new settings"
                                     : "pipeline started again (restart " +
                                           std::to_string(health_.restarts()) + ")")},
                   now);
}

CameraActions CameraMachine::buildFailed(const std::string& why, Clock::time_point now) {
  if (phase_ != CameraPhase::kRestarting) return {};
  // Never silent for good: tried again after the backoff, which grows.
  deadline_ = health_.fault(CameraFault::kError, now);
  return published({logged("its pipeline could not be built (" + why + "): trying again in " +
                           millisecondsUntil(deadline_, now))},
                   now);
}

CameraActions CameraMachine::replan(CameraHealth::Policy policy, bool fileOpen,
                                    Clock::time_point now) {
  CameraActions actions;
  switch (phase_) {
    case CameraPhase::kRunning:
      health_.replan(policy, now);
      actions.push_back(
          logged("its settings changed: closing its file and starting again "
                 "with the new ones"));
      if (fileOpen) {
        actions.push_back({Kind::kEndFile, false, ""});
        phase_ = CameraPhase::kFinishing;
        restartAt_ = now;
        deadline_ = now + kFinishTime;
      } else {
        actions.push_back(action(Kind::kTearDown));
        phase_ = CameraPhase::kRestarting;
        deadline_ = now;
      }
      break;
    case CameraPhase::kFinishing:
    case CameraPhase::kRestarting:
      // A fault's restart is under way: it builds with the new settings,
      // after the fault's backoff still.
      health_.setPolicy(policy);
      break;
    case CameraPhase::kStopping:
    case CameraPhase::kEnded:
      break;
  }
  return published(std::move(actions), now);
}

CameraActions CameraMachine::stop(bool fileOpen, Clock::time_point now) {
  CameraActions actions;
  switch (phase_) {
    case CameraPhase::kRunning:
      if (fileOpen) {
        actions.push_back({Kind::kEndFile, true, ""});
        phase_ = CameraPhase::kStopping;
        deadline_ = now + kFinishTime;
      } else {
        end(actions);
      }
      break;
    case CameraPhase::kFinishing:
      // A fault's finish is under way: its end is the end.
      phase_ = CameraPhase::kStopping;
      break;
    case CameraPhase::kRestarting:
      end(actions);  // no pipeline, nothing to finish
      break;
    case CameraPhase::kStopping:
    case CameraPhase::kEnded:
      break;
  }
  return published(std::move(actions), now);
}

CameraActions CameraMachine::halt(Clock::time_point now) {
  CameraActions actions;
  if (phase_ == CameraPhase::kEnded) return actions;
  end(actions);
  return published(std::move(actions), now);
}

std::optional<CameraMachine::Clock::time_point> CameraMachine::nextDeadline() const {
  switch (phase_) {
    case CameraPhase::kFinishing:
    case CameraPhase::kStopping:
    case CameraPhase::kRestarting:
      return deadline_;
    case CameraPhase::kRunning:
    case CameraPhase::kEnded:
      break;
  }
  return std::nullopt;
}

}  // namespace wircam::recorder
