#include "target_follower.h"

#include <algorithm>

namespace wircam::vision {

const TagSighting* TargetFollower::pickTarget(std::span<const TagSighting> tags, int targetId) {
  const TagSighting* best = nullptr;
  for (const auto& tag : tags) {
    if (targetId >= 0 && tag.id != targetId) continue;
    if (!best || tag.sizePx > best->sizePx) best = &tag;
  }
  return best;
}

FollowStep TargetFollower::step(std::span<const TagSighting> tags, int imageWidth,
                                Clock::time_point now) {
  // The PIDs integrate over real time between frames, capped so that one
  // long stall does not become one huge step.
  double dt = lastStep_ ? std::chrono::duration<double>(now - *lastStep_).count() : 0;
  dt = std::clamp(dt, 0.0, 0.5);
  lastStep_ = now;

  const TagSighting* target = pickTarget(tags, settings_.targetId);
  if (!settings_.enabled) {
    command_ = controller_.neutral();
  } else if (target) {
    command_ = controller_.update(
        TargetObservation{target->centerX, target->sizePx, imageWidth, target->distance}, dt);
    lastSeen_ = now;
  } else if (!command_ || !lastSeen_ || now - *lastSeen_ > settings_.lostTimeout) {
    command_ = controller_.neutral();
  }  // else: briefly out of view, keep the last command
  return {*command_, target != nullptr};
}

}  // namespace wircam::vision
