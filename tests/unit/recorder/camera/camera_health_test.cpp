#include "camera/camera_health.h"

#include <gtest/gtest.h>

namespace {

using namespace wircam::recorder;
using namespace std::chrono_literals;
using Clock = CameraHealth::Clock;

// A camera's health with the default policy (stall after 5 s), from t0.
struct HealthTest : ::testing::Test {
  Clock::time_point t0 = Clock::time_point() + 1000s;
  CameraHealth health{CameraHealth::Policy{}, t0};
};

TEST_F(HealthTest, ConnectingUntilLoggedInAndFramesArrive) {
  EXPECT_EQ(health.state(t0 + 10s), CameraState::kConnecting);
  health.linkUp(t0 + 1s);
  EXPECT_EQ(health.state(t0 + 2s), CameraState::kConnecting);  // its first frame not due yet
  health.frame(t0 + 2s);
  EXPECT_EQ(health.state(t0 + 2s), CameraState::kLive);
  EXPECT_STREQ(toString(health.state(t0 + 2s)), "live");
}

TEST_F(HealthTest, LoggedInWithoutAFrameForTheStallTimeoutIsNoVideoAndAStallOnce) {
  health.linkUp(t0);
  EXPECT_FALSE(health.stalled(t0 + 4999ms));
  EXPECT_TRUE(health.stalled(t0 + 5s));
  EXPECT_EQ(health.state(t0 + 5s), CameraState::kNoVideo);
  EXPECT_STREQ(toString(CameraState::kNoVideo), "no-video");
  health.fault(CameraFault::kStall, t0 + 5s);
  EXPECT_FALSE(health.stalled(t0 + 20s)) << "a stall is a fault once";
  // Restarted, logged in again and still no frame: still no-video, at once.
  health.restarted(t0 + 6s);
  EXPECT_EQ(health.state(t0 + 6s), CameraState::kNoVideo);
  health.linkUp(t0 + 7s);
  EXPECT_EQ(health.state(t0 + 7s), CameraState::kNoVideo);
  EXPECT_TRUE(health.stalled(t0 + 12s));
  health.frame(t0 + 8s);
  EXPECT_EQ(health.state(t0 + 8s), CameraState::kLive);
}

TEST_F(HealthTest, FramesThatStopAreAStallTooAndALossIsOffline) {
  health.linkUp(t0);
  health.frame(t0 + 1s);
  EXPECT_FALSE(health.stalled(t0 + 5s));
  EXPECT_TRUE(health.stalled(t0 + 6s));
  health.frame(t0 + 6s);
  health.linkDown(t0 + 7s);
  EXPECT_EQ(health.state(t0 + 7s), CameraState::kOffline);
  EXPECT_FALSE(health.stalled(t0 + 60s)) << "not logged in: not a stall";
}

TEST_F(HealthTest, RestartsBackOffFromHalfASecondToThirtyAndStartOverOnceHealthy) {
  Clock::time_point now = t0;
  std::vector<Clock::duration> delays;
  for (int i = 0; i < 8; ++i) {
    delays.push_back(health.fault(CameraFault::kError, now) - now);
    now += 1s;
    health.restarted(now);
  }
  std::vector<Clock::duration> expected = {500ms, 1s, 2s, 4s, 8s, 16s, 30s, 30s};
  EXPECT_EQ(delays, expected);
  EXPECT_EQ(health.restarts(), 8u);
  // Frames for less than 10 s after the restart: still backing off.
  health.frame(now + 9s);
  EXPECT_EQ(health.fault(CameraFault::kError, now + 9s) - (now + 9s), 30s);
  health.restarted(now + 10s);
  health.frame(now + 20s);  // 10 s of recording since the restart
  EXPECT_EQ(health.fault(CameraFault::kError, now + 20s) - (now + 20s), 500ms);
}

TEST_F(HealthTest, WhileARestartIsPendingTheStateIsTheFaults) {
  health.linkUp(t0);
  health.frame(t0 + 1s);
  health.linkDown(t0 + 2s);
  health.fault(CameraFault::kLoss, t0 + 2s);
  EXPECT_TRUE(health.restartPending());
  EXPECT_EQ(health.state(t0 + 3s), CameraState::kOffline);
  health.restarted(t0 + 3s);
  EXPECT_FALSE(health.restartPending());
  EXPECT_EQ(health.state(t0 + 3s), CameraState::kOffline);  // was live, not logged in again yet
}

}  // namespace
