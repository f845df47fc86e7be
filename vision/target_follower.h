// The follow policy around FollowController: which tag is the target,
// what to do while it is briefly out of view, when to give up on it
// (lost-timeout) and when not to steer at all (disabled). Time comes from
// the caller, so the policy is tested with a fake clock.
#pragma once

#include <chrono>
#include <optional>
#include <span>

#include "follow_controller.h"

namespace wircam::vision {

// One detected tag as the follower needs it, in the image's pixels.
struct TagSighting {
  int id = 0;
  double centerX = 0;
  double sizePx = 0;               // mean edge length
  std::optional<double> distance;  // m, from pose when known
};

struct FollowerSettings {
  int targetId = -1;  // -1: the largest tag in view
  std::chrono::milliseconds lostTimeout{500};
  bool enabled = true;
};

struct FollowStep {
  FollowCommand command;
  bool targetVisible = false;
};

class TargetFollower {
 public:
  using Clock = std::chrono::steady_clock;

  TargetFollower(FollowConfig config, FollowerSettings settings)
      : controller_(config), settings_(settings) {}

  // New gains or settings; what was seen and when stays.
  void reconfigure(FollowConfig config, FollowerSettings settings) {
    controller_ = FollowController(config);
    settings_ = settings;
  }

  // One frame's tags, seen at `now`.
  FollowStep step(std::span<const TagSighting> tags, int imageWidth, Clock::time_point now);

  // The tag to follow among `tags`, if it is there.
  static const TagSighting* pickTarget(std::span<const TagSighting> tags, int targetId);

 private:
  FollowController controller_;
  FollowerSettings settings_;
  std::optional<Clock::time_point> lastStep_;
  std::optional<Clock::time_point> lastSeen_;
  std::optional<FollowCommand> command_;
};

}  // namespace wircam::vision
