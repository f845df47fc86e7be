// A camera in this process, driven by its own GLib main loop against the
// simulator: the device goes away, the camera's pipeline is to be built
// again, and that build fails once (injected). The camera tries again after
// its backoff and records again when the device is back: no path leaves it
// silent for good.
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <thread>

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

TEST(CameraRebuild, ACameraWhoseRebuildFailsComesBackAndRecords) {
  gst_registry_scan_path(gst_registry_get(), WIRCAM_PLUGIN_DIR);
  auto device = startSequenceDevice();
  ASSERT_TRUE(device);
  uint16_t port = device->port();
  fs::path out = fs::temp_directory_path() / ("camera-rebuild-" + std::to_string(getpid()));
  fs::remove_all(out);
  fs::create_directories(out);
  std::vector<std::string> words = {"wirc-recorder", "--device",
                                    "127.0.0.1:" + std::to_string(port), "--out", out.string()};
  std::vector<char*> argv;
  for (auto& word : words) argv.push_back(word.data());
  auto options = parseOptions(static_cast<int>(argv.size()), argv.data());
  ASSERT_TRUE(options) << options.error();
  auto plan = planPipeline(*options);
  ASSERT_EQ(plan.streams.size(), 1u);
  CameraFiles files{.folder = out.string(), .extension = ".mkv", .limits = {.maxDuration = 0}};
  int builds = 0;
  auto failingOnce =
      [&](const StreamPlan& stream, const CameraFiles& in, FrameTap* frames,
          FrameTap* encoded) -> Expected<std::unique_ptr<CameraPipeline>, std::string> {
    if (++builds == 2) return unexpected(std::string("injected: the build failed"));
    return CameraPipeline::build(stream, in, frames, encoded);
  };
  Observed observed;
  auto camera = Camera::create(plan.streams[0], files, {.stallTimeout = 2s}, observed, failingOnce);
  ASSERT_TRUE(camera) << camera.error();
  ASSERT_TRUE((*camera)->start());
  guint ticks = g_timeout_add(
      Camera::kTickIntervalMs,
      [](gpointer c) -> gboolean {
        static_cast<Camera*>(c)->tick();
        return G_SOURCE_CONTINUE;
      },
      camera->get());
  auto frames = [&] { return (*camera)->report().frames; };
  ASSERT_TRUE(runMainLoopUntil([&] { return frames() > 15; }, 10s));

  // The device goes away: the file ends, the first rebuild fails.
  device.reset();
  ASSERT_TRUE(runMainLoopUntil([&] { return builds >= 2; }, 10s)) << "no rebuild tried";
  EXPECT_EQ((*camera)->phase(), CameraPhase::kRestarting);
  device = startSequenceDevice(port);
  ASSERT_TRUE(device);
  uint64_t before = frames();
  // Tried again after the backoff: it records again.
  EXPECT_TRUE(runMainLoopUntil([&] { return builds >= 3 && frames() > before + 15; }, 20s))
      << builds << " builds, " << frames() << " frames";
  EXPECT_EQ((*camera)->phase(), CameraPhase::kRunning);
  EXPECT_GE((*camera)->report().restarts, 1u);

  (*camera)->stop();
  EXPECT_TRUE(runMainLoopUntil([&] { return observed.over; }, 5s));
  g_source_remove(ticks);
  EXPECT_GE(observed.closed.size(), 2u);  // before the loss, and after it
  camera->reset();
  fs::remove_all(out);
}

TEST(CameraRebuild, BetweenRunsAFollowingCameraStillSaysItFollows) {
  // The status (MQTT, Home Assistant's switch, /api/cameras) said "not
  // following" for each reconnect's seconds, the pipeline being gone.
  gst_registry_scan_path(gst_registry_get(), WIRCAM_PLUGIN_DIR);
  auto device = startFollowDevice();
  ASSERT_TRUE(device);
  fs::path out = fs::temp_directory_path() / ("camera-follow-" + std::to_string(getpid()));
  fs::remove_all(out);
  fs::create_directories(out);
  std::vector<std::string> words = {
      "wirc-recorder", "--device",   "127.0.0.1:" + std::to_string(device->port()),
      "--out",         out.string(), "--detect",
      "tag36h11",      "--follow"};
  std::vector<char*> argv;
  for (auto& word : words) argv.push_back(word.data());
  auto options = parseOptions(static_cast<int>(argv.size()), argv.data());
  ASSERT_TRUE(options) << options.error();
  auto plan = planPipeline(*options);
  ASSERT_EQ(plan.streams.size(), 1u);
  CameraFiles files{.folder = out.string(), .extension = ".mkv", .limits = {.maxDuration = 0}};
  Observed observed;
  auto camera = Camera::create(plan.streams[0], files, {.stallTimeout = 2s}, observed);
  ASSERT_TRUE(camera) << camera.error();
  ASSERT_TRUE((*camera)->start());
  guint ticks = g_timeout_add(
      Camera::kTickIntervalMs,
      [](gpointer c) -> gboolean {
        static_cast<Camera*>(c)->tick();
        return G_SOURCE_CONTINUE;
      },
      camera->get());
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

  (*camera)->stop();
  EXPECT_TRUE(runMainLoopUntil([&] { return observed.over; }, 5s));
  g_source_remove(ticks);
  camera->reset();
  fs::remove_all(out);
}

}  // namespace
