// TargetFollower with a fake clock: target choice, lost-timeout, enabled.
#include "target_follower.h"

#include <gtest/gtest.h>

namespace wircam::vision {
namespace {

using std::chrono::milliseconds;
using Clock = TargetFollower::Clock;

constexpr int kWidth = 352;
const TagSighting kLeftTag{.id = 3, .centerX = 60, .sizePx = 40};

class TargetFollowerTest : public ::testing::Test {
 protected:
  FollowConfig config;
  Clock::time_point t0 = Clock::now();
  Clock::time_point at(int ms) { return t0 + milliseconds(ms); }
  bool neutral(const FollowStep& step) {
    return step.command.steeringPulse == config.steeringMap.neutral &&
           step.command.throttlePulse == config.throttleMap.neutral;
  }
};

TEST_F(TargetFollowerTest, PicksTheNamedTagOrElseTheLargest) {
  std::vector<TagSighting> tags = {{.id = 1, .sizePx = 10}, {.id = 2, .sizePx = 30}};
  EXPECT_EQ(TargetFollower::pickTarget(tags, -1)->id, 2);
  EXPECT_EQ(TargetFollower::pickTarget(tags, 1)->id, 1);
  EXPECT_EQ(TargetFollower::pickTarget(tags, 9), nullptr);
}

TEST_F(TargetFollowerTest, SteersTowardsATagOnTheLeft) {
  TargetFollower follower(config, {});
  follower.step(std::span(&kLeftTag, 1), kWidth, at(0));
  auto step = follower.step(std::span(&kLeftTag, 1), kWidth, at(100));
  EXPECT_TRUE(step.targetVisible);
  EXPECT_GT(step.command.steeringPulse, config.steeringMap.neutral);  // 2000 = left
}

TEST_F(TargetFollowerTest, KeepsTheLastCommandWhileTheTagIsBrieflyOutOfView) {
  TargetFollower follower(config, {.lostTimeout = milliseconds(500)});
  follower.step(std::span(&kLeftTag, 1), kWidth, at(0));
  auto seen = follower.step(std::span(&kLeftTag, 1), kWidth, at(100));
  auto unseen = follower.step({}, kWidth, at(600));
  EXPECT_FALSE(unseen.targetVisible);
  EXPECT_EQ(unseen.command.steeringPulse, seen.command.steeringPulse);
}

TEST_F(TargetFollowerTest, GoesNeutralOnceTheTagIsUnseenForLongerThanLostTimeout) {
  TargetFollower follower(config, {.lostTimeout = milliseconds(500)});
  follower.step(std::span(&kLeftTag, 1), kWidth, at(0));
  follower.step(std::span(&kLeftTag, 1), kWidth, at(100));
  EXPECT_TRUE(neutral(follower.step({}, kWidth, at(601))));
}

TEST_F(TargetFollowerTest, HoldsNeutralWhenDisabledEvenWithTheTagInView) {
  TargetFollower follower(config, {.enabled = false});
  follower.step(std::span(&kLeftTag, 1), kWidth, at(0));
  EXPECT_TRUE(neutral(follower.step(std::span(&kLeftTag, 1), kWidth, at(100))));
}

TEST_F(TargetFollowerTest, StartsNeutralWithNoTagInView) {
  TargetFollower follower(config, {});
  EXPECT_TRUE(neutral(follower.step({}, kWidth, at(0))));
}

}  // namespace
}  // namespace wircam::vision
