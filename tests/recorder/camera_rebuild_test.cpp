// A camera in this process, driven by its own GLib main loop against the
// simulator: the device goes away, the camera's pipeline is to be built
// again, and that build fails once (injected). The camera tries again after
// its backoff and records again when the device is back: no path leaves it
// silent for good.
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <optional>
#include <thread>
#include <utility>

#include "app/pipeline_planner.h"
#include "camera/camera.h"
#include "camera_events.h"
#include "simulated_device.h"
#include "wait_for.h"

namespace {

namespace fs = std::filesystem;
using namespace wircam;
using namespace wircam::recorder;
using namespace wircam::testing;
using namespace std::chrono_literals;

using Observed = wircam::testing::CameraEvents;
using wircam::testing::runMainLoopUntil;

// A camera in this process: its recording folder, its plan from a
// recorder's command line, and the tick its supervisor would give it.
class CameraRebuild : public ::testing::Test {
 protected:
  void SetUp() override {
    gst_registry_scan_path(gst_registry_get(), WIRCAM_PLUGIN_DIR);
    fs::remove_all(out_);
    fs::create_directories(out_);
  }
  void TearDown() override {
    if (ticks_) g_source_remove(ticks_);
    fs::remove_all(out_);
  }

  // The one stream `wirc-recorder --out FOLDER WORDS...` plans.
  std::optional<StreamPlan> streamOf(std::vector<std::string> words) {
    words.insert(words.begin(), {"wirc-recorder", "--out", out_.string()});
    std::vector<char*> argv;
    for (auto& word : words) argv.push_back(word.data());
    auto options = parseOptions(static_cast<int>(argv.size()), argv.data());
    if (!options) {
      ADD_FAILURE() << options.error();
      return std::nullopt;
    }
    auto plan = planPipeline(*options);
    if (plan.streams.size() != 1) return std::nullopt;
    return plan.streams[0];
  }
  CameraFiles files() const {
    return {.folder = out_.string(), .extension = ".mkv", .limits = {.maxDuration = 0}};
  }
  void tick(Camera& camera) {
    ticks_ = g_timeout_add(
        Camera::kTickIntervalMs,
        [](gpointer c) -> gboolean {
          static_cast<Camera*>(c)->tick();
          return G_SOURCE_CONTINUE;
        },
        &camera);
  }
  // Stops the camera and runs the loop until it has ended.
  bool stop(Camera& camera, Observed& observed) {
    camera.stop();
    bool ended = runMainLoopUntil([&] { return observed.over; }, 5s);
    g_source_remove(std::exchange(ticks_, 0));
    return ended;
  }

 private:
  fs::path out_ = fs::temp_directory_path() / ("camera-rebuild-" + std::to_string(getpid()));
  guint ticks_ = 0;
};

TEST_F(CameraRebuild, ACameraWhoseRebuildFailsComesBackAndRecords) {
  auto device = startSequenceDevice();
  ASSERT_TRUE(device);
  uint16_t port = device->port();
  auto stream = streamOf({"--device", "127.0.0.1:" + std::to_string(port)});
  ASSERT_TRUE(stream);
  int builds = 0;
  auto failingOnce =
      [&](const StreamPlan& plan, const CameraFiles& in, FrameTap* frames,
          FrameTap* encoded) -> Expected<std::unique_ptr<CameraPipeline>, std::string> {
    if (++builds == 2) return unexpected(std::string("injected: the build failed"));
    return CameraPipeline::build(plan, in, frames, encoded);
  };
  Observed observed;
  auto camera = Camera::create(*stream, files(), {.stallTimeout = 2s}, observed, failingOnce);
  ASSERT_TRUE(camera) << camera.error();
  ASSERT_TRUE((*camera)->start());
  tick(**camera);
  auto frames = [&] { return (*camera)->report().frames; };
  ASSERT_TRUE(runMainLoopUntil([&] { return frames() > 15; }, 10s));

  // The device goes away: the file ends, the first rebuild fails.
  HeldPort off = switchOff(device);
  ASSERT_TRUE(runMainLoopUntil([&] { return builds >= 2; }, 10s)) << "no rebuild tried";
  EXPECT_EQ((*camera)->phase(), CameraPhase::kRestarting);
  device = switchOn(off);
  ASSERT_TRUE(device);
  uint64_t before = frames();
  // Tried again after the backoff: it records again.
  EXPECT_TRUE(runMainLoopUntil([&] { return builds >= 3 && frames() > before + 15; }, 20s))
      << builds << " builds, " << frames() << " frames";
  EXPECT_EQ((*camera)->phase(), CameraPhase::kRunning);
  EXPECT_GE((*camera)->report().restarts, 1u);

  EXPECT_TRUE(stop(**camera, observed));
  EXPECT_GE(observed.closed.size(), 2u);  // before the loss, and after it
}

TEST_F(CameraRebuild, BetweenRunsAFollowingCameraStillSaysItFollows) {
  // The status (MQTT, Home Assistant's switch, /api/cameras) said "not
  // following" for each reconnect's seconds, the pipeline being gone.
  auto device = startFollowDevice();
  ASSERT_TRUE(device);
  auto stream = streamOf({"--device", "127.0.0.1:" + std::to_string(device->port()), "--detect",
                          "tag36h11", "--follow"});
  ASSERT_TRUE(stream);
  Observed observed;
  auto camera = Camera::create(*stream, files(), {.stallTimeout = 2s}, observed);
  ASSERT_TRUE(camera) << camera.error();
  ASSERT_TRUE((*camera)->start());
  tick(**camera);
  auto following = [&] {
    auto control = (*camera)->report().control;
    return control && control->following;
  };
  ASSERT_TRUE(runMainLoopUntil([&] { return (*camera)->report().frames > 5 && following(); }, 10s));

  device.reset();  // gone: the file ends, the pipeline is torn down until the device is back
  ASSERT_TRUE(runMainLoopUntil(
      [&] { return (*camera)->phase() == CameraPhase::kRestarting && !(*camera)->controller(); },
      10s));
  EXPECT_TRUE(following());
  EXPECT_FALSE((*camera)->report().control->hasControl);

  EXPECT_TRUE(stop(**camera, observed));
}

}  // namespace
