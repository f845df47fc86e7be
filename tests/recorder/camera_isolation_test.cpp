// One camera's trouble stays its own: a device that logs in and never
// streams (a WiRC with its camera unplugged, a stream port behind a
// firewall) holds up neither another camera's recording nor the stop.
#include <gtest/gtest.h>
#include <signal.h>

#include "camera_checks.h"
#include "http_fetch.h"
#include "simulated_device.h"
#include "wait_for.h"

namespace {

namespace fs = std::filesystem;
using namespace wircam::testing;
using namespace std::chrono_literals;
using Clock = std::chrono::steady_clock;

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
  std::string camera = cameraName(good->port());
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
  expectSigintEndsItWithinThreeSeconds(recorder);
  std::string camera = cameraName(good->port());
  EXPECT_GT(indexedFrames(recorder.out(), camera), 0u) << recorder.log();
}

TEST(CameraIsolation, ASilentDeviceIsNoVideoAndStartedAgainWhileTheOtherRecords) {
  auto good = startSequenceDevice();
  ASSERT_TRUE(good);
  SilentCamera silent;
  RecorderProcess recorder(
      good->port(), {"--device", silent.device(), "--stall-timeout", "1", "--http", "127.0.0.1:0"});
  auto url = recorder.waitForLog("http://", 5000ms);
  ASSERT_TRUE(url) << recorder.log();
  std::string silentName = cameraName(silent.peer.port());
  std::string goodName = cameraName(good->port());
  EXPECT_TRUE(waitFor([&] { return cameraEntry(*url, silentName)["state"] == "no-video"; }, 10s))
      << cameraEntry(*url, silentName) << recorder.log();
  // Its pipeline is torn down and started again (and logs in again).
  EXPECT_TRUE(waitFor([&] { return silent.peer.connections() >= 2; }, 10s)) << recorder.log();
  EXPECT_NE(recorder.log().find(silentName + ": no frame for 1000 ms while logged in"),
            std::string::npos)
      << recorder.log();
  EXPECT_EQ(cameraEntry(*url, goodName)["state"], "live");
  EXPECT_GE(streamEntry(*url, silentName)["restarts"].get<int>(), 1);
  expectSigintEndsItWithinThreeSeconds(recorder);
  EXPECT_GT(indexedFrames(recorder.out(), goodName), 15u) << recorder.log();
  EXPECT_EQ(indexedFrames(recorder.out(), silentName), 0u);
}

TEST(CameraIsolation, AVanishedDeviceHasItsFileFinishedAndIndexedWithinTheLinkTimeout) {
  auto device = startSequenceDevice();
  ASSERT_TRUE(device);
  uint16_t port = device->port();
  RecorderProcess recorder(port, {"--segment", "60", "--http", "127.0.0.1:0"});
  auto url = recorder.waitForLog("http://", 5000ms);
  ASSERT_TRUE(url) << recorder.log();
  std::string name = cameraName(port);
  ASSERT_TRUE(waitFor([&] { return cameraEntry(*url, name)["state"] == "live"; }, 10s))
      << recorder.log();
  // Two seconds of frames.
  ASSERT_TRUE(waitFor(
      [&] {
        auto status = nlohmann::json::parse(fetch(*url + "api/status").body, nullptr, false);
        return status.is_object() && status["streams"][0]["frames"].get<int>() >= 30;
      },
      10s));
  HeldPort off = switchOff(device);
  auto vanished = Clock::now();
  // The link times out (2 s), then the file is finished: in the index, no
  // longer the open segment, its length readable.
  ASSERT_TRUE(waitFor([&] { return indexedFrames(recorder.out(), name) > 0; }, patience(4000ms)))
      << recorder.log();
  EXPECT_LT(Clock::now() - vanished, patience(3500ms));
  EXPECT_EQ(cameraEntry(*url, name)["state"], "offline");
  auto status = nlohmann::json::parse(fetch(*url + "api/status").body);
  EXPECT_EQ(status["streams"][0]["segment"], "") << status;
  auto videos = recorder.files(".mkv");
  ASSERT_EQ(videos.size(), 1u);
  EXPECT_GT(durationOf(videos[0]), GST_SECOND);
  // The device comes back: the next file starts with its first frame.
  device = switchOn(off);
  ASSERT_TRUE(device);
  EXPECT_TRUE(waitFor([&] { return recorder.files(".mkv").size() == 2; }, 15s)) << recorder.log();
  recorder.signal(SIGINT);
  ASSERT_EQ(recorder.waitExit(patience(3000ms)), 0) << recorder.log();
}

}  // namespace
