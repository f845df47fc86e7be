// What a reload does to each camera: by name, from what the cameras run
// and what the options now plan.
#include "app/reload_plan.h"

#include <gtest/gtest.h>

#include "app/pipeline_planner.h"

namespace wircam::recorder {
namespace {

using Names = std::vector<std::string>;

std::vector<StreamPlan> streamsOf(std::initializer_list<const char*> args) {
  std::vector<char*> argv{const_cast<char*>("wirc-recorder")};
  for (const char* a : args) argv.push_back(const_cast<char*>(a));
  auto options = parseOptions(static_cast<int>(argv.size()), argv.data());
  EXPECT_TRUE(options) << (options ? "" : options.error());
  return options ? planPipeline(*options).streams : std::vector<StreamPlan>{};
}

// Cameras running `streams`, with these files and this policy.
struct Running {
  std::vector<StreamPlan> streams;
  CameraFiles files{.folder = "/rec", .extension = ".mkv"};
  CameraHealth::Policy policy;

  std::vector<RunningCamera> cameras() const {
    std::vector<RunningCamera> seen;
    for (const auto& stream : streams) seen.push_back({stream, files, policy});
    return seen;
  }
};

const std::vector<StreamPlan> kTwo =
    streamsOf({"--device", "10.0.0.2", "--device", "10.0.0.3", "--out", "/rec"});

TEST(ReloadPlan, TheSameOptionsLeaveEveryCameraRecording) {
  Running running{kTwo};
  auto plan = planReload(running.cameras(), kTwo, running.files, running.policy);
  EXPECT_EQ(plan.unchanged, (Names{"10.0.0.2-cam0", "10.0.0.3-cam0"}));
  EXPECT_TRUE(plan.added.empty() && plan.removed.empty() && plan.restarted.empty());
}

TEST(ReloadPlan, ADeviceAddedStartsAndADeviceGoneStopsTheOtherRecordsOn) {
  Running running{kTwo};
  auto now = streamsOf({"--device", "10.0.0.3", "--device", "10.0.0.4", "--out", "/rec"});
  auto plan = planReload(running.cameras(), now, running.files, running.policy);
  EXPECT_EQ(plan.added, Names{"10.0.0.4-cam0"});
  EXPECT_EQ(plan.removed, Names{"10.0.0.2-cam0"});
  EXPECT_EQ(plan.unchanged, Names{"10.0.0.3-cam0"});
  EXPECT_TRUE(plan.restarted.empty());
}

TEST(ReloadPlan, OnlyTheCameraWhoseStreamChangedRestarts) {
  Running running{kTwo};
  auto now = kTwo;
  now[1].description += " detect-every=2";  // as a [device] section's change makes it
  auto plan = planReload(running.cameras(), now, running.files, running.policy);
  EXPECT_EQ(plan.restarted, Names{"10.0.0.3-cam0"});
  EXPECT_EQ(plan.unchanged, Names{"10.0.0.2-cam0"});
}

TEST(ReloadPlan, FilesOrAHealthPolicyChangedRestartEveryCamera) {
  Running running{kTwo};
  auto longer = running.files;
  longer.limits.maxDuration = running.files.limits.maxDuration + 1;
  auto files = planReload(running.cameras(), kTwo, longer, running.policy);
  EXPECT_EQ(files.restarted, (Names{"10.0.0.2-cam0", "10.0.0.3-cam0"}));
  auto patient = running.policy;
  patient.stallTimeout *= 2;
  auto health = planReload(running.cameras(), kTwo, running.files, patient);
  EXPECT_EQ(health.restarted, (Names{"10.0.0.2-cam0", "10.0.0.3-cam0"}));
}

TEST(ReloadPlan, ACameraStillFinishingIsNotRunningSoItsNameComesBackAsAdded) {
  // The supervisor leaves out a camera a reload removed until its file is
  // finished: its stream planned again starts a camera of its own.
  Running running{{kTwo[1]}};
  auto plan = planReload(running.cameras(), kTwo, running.files, running.policy);
  EXPECT_EQ(plan.added, Names{"10.0.0.2-cam0"});
  EXPECT_EQ(plan.unchanged, Names{"10.0.0.3-cam0"});
}

TEST(ReloadPlan, SummarisedAsTheApiAnswersIt) {
  ReloadPlan plan{.added = {"a"}, .removed = {}, .restarted = {"b"}, .unchanged = {"c", "d"}};
  EXPECT_EQ(plan.summary(), nlohmann::json::parse(R"({"added": ["a"], "removed": [],
      "restarted": ["b"], "unchanged": ["c", "d"]})"));
}

}  // namespace
}  // namespace wircam::recorder
