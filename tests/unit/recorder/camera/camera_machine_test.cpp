// CameraMachine with time passed in: every transition of a camera's
// lifecycle, without a pipeline or a clock.
#include "camera/camera_machine.h"

#include <gtest/gtest.h>

#include <algorithm>

namespace {

using namespace wircam::recorder;
using namespace std::chrono_literals;
using Clock = CameraMachine::Clock;
using Kind = CameraAction::Kind;

bool has(const CameraActions& actions, Kind kind) {
  return std::any_of(actions.begin(), actions.end(), [&](const auto& a) { return a.kind == kind; });
}
std::vector<Kind> kindsOf(const CameraActions& actions) {
  std::vector<Kind> kinds;
  for (const auto& a : actions)
    if (a.kind != Kind::kLog && a.kind != Kind::kPublishState) kinds.push_back(a.kind);
  return kinds;
}
std::string logOf(const CameraActions& actions) {
  std::string text;
  for (const auto& a : actions)
    if (a.kind == Kind::kLog) text += a.text + "\n";
  return text;
}

// A camera logged in and recording (a file open), from t0; stall after 5 s,
// restarts after 0.5 s doubling.
struct MachineTest : ::testing::Test {
  Clock::time_point t0 = Clock::time_point() + 1000s;
  CameraMachine machine{CameraHealth::Policy{}, t0};
  void SetUp() override {
    machine.linkUp(t0);
    machine.frame(t0 + 100ms);
  }
  // A stall's fault with the file open, at t0 + 6 s.
  CameraActions stall() { return machine.tick(true, t0 + 6s); }
};

TEST_F(MachineTest, LiveCamerasSayTheirStateAndNeedNoDeadline) {
  EXPECT_EQ(machine.phase(), CameraPhase::kRunning);
  EXPECT_EQ(machine.health().state(t0 + 1s), CameraState::kLive);
  EXPECT_EQ(machine.nextDeadline(), std::nullopt);
  EXPECT_TRUE(machine.tick(true, t0 + 1s).empty());
  EXPECT_STREQ(toString(CameraPhase::kRestarting), "restarting");
}

TEST_F(MachineTest, AStallEndsTheFileThenRestartsAfterTheBackoff) {
  auto faulted = stall();
  EXPECT_EQ(kindsOf(faulted), std::vector<Kind>{Kind::kEndFile});
  EXPECT_FALSE(faulted.front().forGood);
  EXPECT_TRUE(has(faulted, Kind::kPublishState));  // no-video
  EXPECT_NE(logOf(faulted).find("no frame for 5000 ms while logged in: closing its file and "
                                "starting its pipeline again in 500 ms"),
            std::string::npos)
      << logOf(faulted);
  EXPECT_EQ(machine.phase(), CameraPhase::kFinishing);
  EXPECT_TRUE(machine.betweenRuns());
  EXPECT_EQ(machine.nextDeadline(), t0 + 6s + CameraMachine::kFinishTime);
  // The file's EOS: torn down, the next run due at the backoff's end.
  EXPECT_EQ(kindsOf(machine.endOfStream(t0 + 6100ms)), std::vector<Kind>{Kind::kTearDown});
  EXPECT_EQ(machine.phase(), CameraPhase::kRestarting);
  EXPECT_EQ(machine.nextDeadline(), t0 + 6500ms);
  EXPECT_TRUE(machine.tick(false, t0 + 6400ms).empty());
  EXPECT_EQ(kindsOf(machine.tick(false, t0 + 6500ms)), std::vector<Kind>{Kind::kBuild});
  auto started = machine.built(t0 + 6500ms);
  EXPECT_NE(logOf(started).find("pipeline started again (restart 1)"), std::string::npos);
  EXPECT_EQ(machine.phase(), CameraPhase::kRunning);
  EXPECT_EQ(machine.health().restarts(), 1u);
}

TEST_F(MachineTest, AFailedBuildIsTriedAgainAfterAGrowingBackoffUntilItSucceeds) {
  stall();
  machine.endOfStream(t0 + 6100ms);
  machine.tick(false, t0 + 6500ms);
  auto failed = machine.buildFailed("no element \"wircsrc\"", t0 + 6500ms);
  EXPECT_NE(logOf(failed).find("its pipeline could not be built (no element \"wircsrc\"): "
                               "trying again in 1000 ms"),
            std::string::npos)
      << logOf(failed);
  EXPECT_EQ(machine.phase(), CameraPhase::kRestarting);
  EXPECT_EQ(machine.nextDeadline(), t0 + 7500ms);
  machine.tick(false, t0 + 7500ms);
  machine.buildFailed("again", t0 + 7500ms);
  EXPECT_EQ(machine.nextDeadline(), t0 + 9500ms);  // 2 s
  EXPECT_EQ(kindsOf(machine.tick(false, t0 + 9500ms)), std::vector<Kind>{Kind::kBuild});
  machine.built(t0 + 9500ms);
  EXPECT_EQ(machine.phase(), CameraPhase::kRunning);
}

TEST_F(MachineTest, EosThatNeverComesIsCutOffAtTheDeadline) {
  stall();
  EXPECT_TRUE(machine.tick(true, t0 + 8499ms).empty());
  auto cut = machine.tick(true, t0 + 8500ms);
  EXPECT_EQ(kindsOf(cut), std::vector<Kind>{Kind::kTearDown});
  EXPECT_NE(logOf(cut).find("cut off after 2500 ms"), std::string::npos);
  // The restart was due at 6.5 s: at once.
  EXPECT_EQ(machine.nextDeadline(), t0 + 6500ms);
  EXPECT_EQ(kindsOf(machine.tick(false, t0 + 8500ms)), std::vector<Kind>{Kind::kBuild});
}

TEST_F(MachineTest, AnErrorWhileFinishingTearsDownAndRestarts) {
  stall();
  auto error = machine.pipelineError(t0 + 6200ms);
  EXPECT_EQ(kindsOf(error), std::vector<Kind>{Kind::kTearDown});
  EXPECT_EQ(machine.phase(), CameraPhase::kRestarting);
  EXPECT_EQ(machine.nextDeadline(), t0 + 6500ms);
}

TEST_F(MachineTest, FramesReturningDuringTheStallsFinishDoNotUndoIt) {
  stall();
  EXPECT_TRUE(kindsOf(machine.frame(t0 + 6100ms)).empty());
  EXPECT_TRUE(kindsOf(machine.tick(true, t0 + 6200ms)).empty()) << "no second fault";
  EXPECT_EQ(machine.phase(), CameraPhase::kFinishing);
  EXPECT_EQ(kindsOf(machine.endOfStream(t0 + 6300ms)), std::vector<Kind>{Kind::kTearDown});
  machine.tick(false, t0 + 6500ms);
  machine.built(t0 + 6500ms);
  machine.linkUp(t0 + 6600ms);
  machine.frame(t0 + 6700ms);
  EXPECT_EQ(machine.health().state(t0 + 6700ms), CameraState::kLive);
}

TEST_F(MachineTest, AStopDuringARestartsBackoffEndsAtOnce) {
  stall();
  machine.endOfStream(t0 + 6100ms);
  auto stopped = machine.stop(false, t0 + 6200ms);
  EXPECT_EQ(kindsOf(stopped), std::vector<Kind>{Kind::kEnded});
  EXPECT_EQ(machine.phase(), CameraPhase::kEnded);
  EXPECT_EQ(machine.nextDeadline(), std::nullopt);
  EXPECT_TRUE(machine.tick(false, t0 + 7s).empty()) << "nothing is built after the end";
}

TEST_F(MachineTest, AStopFinishesTheFileForGoodThenEnds) {
  auto stopping = machine.stop(true, t0 + 1s);
  ASSERT_EQ(kindsOf(stopping), std::vector<Kind>{Kind::kEndFile});
  EXPECT_TRUE(stopping.front().forGood);
  EXPECT_FALSE(machine.betweenRuns());
  EXPECT_EQ(machine.nextDeadline(), t0 + 1s + CameraMachine::kFinishTime);
  EXPECT_TRUE(machine.stop(true, t0 + 1100ms).empty()) << "a second stop changes nothing";
  EXPECT_EQ(kindsOf(machine.endOfStream(t0 + 1200ms)),
            (std::vector<Kind>{Kind::kTearDown, Kind::kEnded}));
}

TEST_F(MachineTest, AStopWithoutAFileEndsAtOnceAndOneDuringAFaultsFinishEndsWithIt) {
  CameraMachine quiet{CameraHealth::Policy{}, t0};
  EXPECT_EQ(kindsOf(quiet.stop(false, t0)), (std::vector<Kind>{Kind::kTearDown, Kind::kEnded}));
  stall();
  EXPECT_TRUE(kindsOf(machine.stop(true, t0 + 6100ms)).empty());
  EXPECT_EQ(machine.phase(), CameraPhase::kStopping);
  // EOS never comes: cut off at the fault's deadline, and ended.
  EXPECT_EQ(kindsOf(machine.tick(true, t0 + 8500ms)),
            (std::vector<Kind>{Kind::kTearDown, Kind::kEnded}));
}

TEST_F(MachineTest, AnErrorRestartsAtOnceWithoutEndingTheFile) {
  auto error = machine.pipelineError(t0 + 1s);
  EXPECT_EQ(kindsOf(error), std::vector<Kind>{Kind::kTearDown});
  EXPECT_NE(logOf(error).find("restarting its pipeline after the error above in 500 ms; the other "
                              "cameras record on"),
            std::string::npos)
      << logOf(error);
  EXPECT_EQ(machine.nextDeadline(), t0 + 1500ms);
}

TEST_F(MachineTest, APipelineThatEndsByItselfIsRestarted) {
  EXPECT_EQ(kindsOf(machine.endOfStream(t0 + 1s)), std::vector<Kind>{Kind::kTearDown});
  EXPECT_EQ(machine.phase(), CameraPhase::kRestarting);
  EXPECT_EQ(machine.nextDeadline(), t0 + 1500ms);
}

TEST_F(MachineTest, ALossWithAFileOpenEndsItAndOneWithoutOnlySaysSo) {
  auto lost = machine.linkLost(true, t0 + 1s);
  EXPECT_EQ(kindsOf(lost), std::vector<Kind>{Kind::kEndFile});
  EXPECT_EQ(machine.health().state(t0 + 1s), CameraState::kOffline);
  CameraMachine empty{CameraHealth::Policy{}, t0};
  empty.linkUp(t0);
  auto said = empty.linkLost(false, t0 + 1s);
  EXPECT_TRUE(kindsOf(said).empty());
  EXPECT_TRUE(has(said, Kind::kPublishState));
  EXPECT_EQ(empty.phase(), CameraPhase::kRunning);
}

TEST_F(MachineTest, AStallWithNoFileTearsDownAtOnce) {
  CameraMachine silent{CameraHealth::Policy{}, t0};
  silent.linkUp(t0);
  EXPECT_EQ(kindsOf(silent.tick(false, t0 + 5s)), std::vector<Kind>{Kind::kTearDown});
  EXPECT_EQ(silent.phase(), CameraPhase::kRestarting);
  EXPECT_EQ(silent.health().state(t0 + 5s), CameraState::kNoVideo);
}

TEST_F(MachineTest, AFullDiskOrAHaltEndsAtOnce) {
  EXPECT_EQ(kindsOf(machine.diskFull(t0 + 1s)), (std::vector<Kind>{Kind::kTearDown, Kind::kEnded}));
  EXPECT_TRUE(machine.halt(t0 + 2s).empty());
  CameraMachine other{CameraHealth::Policy{}, t0};
  other.stop(true, t0);
  EXPECT_EQ(kindsOf(other.halt(t0 + 1s)), (std::vector<Kind>{Kind::kTearDown, Kind::kEnded}));
}

}  // namespace

// New settings (a reload): the file finished, a pipeline with them built at
// once, with no backoff and no restart counted; the new stall timeout holds.
TEST_F(MachineTest, NewSettingsFinishTheFileThenBuildAtOnceWithoutAFault) {
  CameraHealth::Policy quicker{.stallTimeout = 2s};
  auto replanned = machine.replan(quicker, true, t0 + 1s);
  EXPECT_EQ(kindsOf(replanned), std::vector<Kind>{Kind::kEndFile});
  EXPECT_FALSE(replanned.front().forGood);
  EXPECT_NE(logOf(replanned).find("settings changed"), std::string::npos);
  EXPECT_EQ(machine.phase(), CameraPhase::kFinishing);
  // The file's EOS: torn down and due for a build now, not after a backoff.
  auto finished = machine.endOfStream(t0 + 1200ms);
  EXPECT_EQ(kindsOf(finished), std::vector<Kind>{Kind::kTearDown});
  EXPECT_EQ(machine.nextDeadline(), t0 + 1s);
  EXPECT_EQ(kindsOf(machine.tick(false, t0 + 1200ms)), std::vector<Kind>{Kind::kBuild});
  machine.built(t0 + 1300ms);
  EXPECT_EQ(machine.phase(), CameraPhase::kRunning);
  EXPECT_EQ(machine.health().restarts(), 0u);
  machine.linkUp(t0 + 1400ms);
  machine.frame(t0 + 1500ms);
  EXPECT_TRUE(kindsOf(machine.tick(true, t0 + 3400ms)).empty());
  EXPECT_EQ(kindsOf(machine.tick(true, t0 + 3600ms)), std::vector<Kind>{Kind::kEndFile});
}

TEST_F(MachineTest, NewSettingsWithNoFileOpenRebuildAtOnce) {
  auto replanned = machine.replan({}, false, t0 + 1s);
  EXPECT_EQ(kindsOf(replanned), std::vector<Kind>{Kind::kTearDown});
  EXPECT_EQ(kindsOf(machine.tick(false, t0 + 1s)), std::vector<Kind>{Kind::kBuild});
}

TEST_F(MachineTest, NewSettingsDuringAFaultsRestartKeepItsBackoffAndCountIt) {
  stall();
  machine.endOfStream(t0 + 6100ms);
  EXPECT_TRUE(machine.replan({}, false, t0 + 6200ms).empty());
  EXPECT_TRUE(kindsOf(machine.tick(false, t0 + 6300ms)).empty());  // backoff: 500 ms
  EXPECT_EQ(kindsOf(machine.tick(false, t0 + 6600ms)), std::vector<Kind>{Kind::kBuild});
  machine.built(t0 + 6700ms);
  EXPECT_EQ(machine.health().restarts(), 1u);
}

TEST_F(MachineTest, NewSettingsAfterAStopChangeNothing) {
  machine.stop(true, t0 + 1s);
  EXPECT_TRUE(machine.replan({}, true, t0 + 1100ms).empty());
  EXPECT_EQ(machine.phase(), CameraPhase::kStopping);
}

TEST_F(MachineTest, ACameraStartedWithNewSettingsIsConnectingNotOffline) {
  machine.replan({}, false, t0 + 1s);
  machine.tick(false, t0 + 1s);
  machine.built(t0 + 1100ms);
  EXPECT_EQ(machine.health().state(t0 + 1200ms), CameraState::kConnecting);
}
