// One camera's trouble stays its own: a device that logs in and never
// streams (a WiRC with its camera unplugged, a stream port behind a
// firewall) holds up neither another camera's recording nor the stop.
#include <gtest/gtest.h>
#include <signal.h>

#include <fstream>
#include <nlohmann/json.hpp>

#include "misbehaving_peers.h"
#include "recorder_process.h"
#include "simulated_device.h"
#include "wait_for.h"

namespace {

namespace fs = std::filesystem;
using namespace wircam::testing;
using namespace std::chrono_literals;
using Clock = std::chrono::steady_clock;

// Logs in (WST), reports its status once, and never sends a frame: the
// recorder logs in again after each link timeout, and still no frame.
struct SilentCamera {
  ScriptedPeer peer;
  SilentCamera() { peer.play({.chunks = {peer.wst()}, .statusReports = 1}); }
  std::string device() const { return "127.0.0.1:" + std::to_string(peer.port()); }
};

// The index's segments of `camera` and the frames they hold.
uint64_t indexedFrames(const fs::path& out, const std::string& camera) {
  std::ifstream in(out / "index.json");
  auto index = nlohmann::json::parse(in, nullptr, false);
  uint64_t frames = 0;
  if (index.is_object())
    for (const auto& segment : index["segments"])
      if (segment["camera"] == camera) frames += segment["frames"].get<uint64_t>();
  return frames;
}

TEST(CameraIsolation, ASilentDeviceHoldsUpNeitherTheOtherCameraNorTheDuration) {
  auto good = startSequenceDevice();
  ASSERT_TRUE(good);
  SilentCamera silent;
  RecorderProcess recorder(good->port(), {"--device", silent.device(), "--duration", "4"});
  // --duration, then a stop bounded by 3 s (and the start-up).
  auto code = recorder.waitExit(patience(4000ms + 3000ms + 2000ms));
  ASSERT_TRUE(code.has_value()) << "still running" << recorder.log();
  EXPECT_EQ(*code, 0) << recorder.log();
  auto videos = recorder.files(".mkv");
  ASSERT_EQ(videos.size(), 1u) << "the good camera's alone";
  EXPECT_GT(fs::file_size(videos[0]), 100'000u);
  // 15 fps for most of 4 s, finished and indexed.
  std::string camera = "127.0.0.1-" + std::to_string(good->port()) + "-cam0";
  EXPECT_GT(indexedFrames(recorder.out(), camera), 40u) << recorder.log();
}

TEST(CameraIsolation, ASignalEndsTheRecorderWithinThreeSecondsWhateverASilentDeviceDoes) {
  auto good = startSequenceDevice();
  ASSERT_TRUE(good);
  SilentCamera silent;
  RecorderProcess recorder(good->port(), {"--device", silent.device(), "--duration", "60"});
  // Recording: the good camera's file grows.
  ASSERT_TRUE(waitFor(
      [&] {
        auto videos = recorder.files(".mkv");
        return !videos.empty() && fs::file_size(videos[0]) > 50'000;
      },
      10s))
      << recorder.log();
  auto signalled = Clock::now();
  recorder.signal(SIGINT);
  auto code = recorder.waitExit(patience(3000ms));
  ASSERT_TRUE(code.has_value()) << "still running 3 s after SIGINT" << recorder.log();
  EXPECT_EQ(*code, 0) << recorder.log();
  EXPECT_LT(Clock::now() - signalled, patience(3000ms));
  std::string camera = "127.0.0.1-" + std::to_string(good->port()) + "-cam0";
  EXPECT_GT(indexedFrames(recorder.out(), camera), 0u) << recorder.log();
}

}  // namespace
