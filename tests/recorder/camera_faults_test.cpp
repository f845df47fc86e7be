// The bad inputs a recorder of many cameras meets, one camera at a time:
// datagrams that go elsewhere, an error on one camera's file, a device that
// restarts while the recorder stops, and a fleet in which some devices
// never answer. In each case the others record on and the stop ends
// within 3 s.
#include <gtest/gtest.h>
#include <poll.h>
#include <signal.h>

#include <chrono>
#include <ctime>

#include "camera_checks.h"
#include "common/socket.h"
#include "http_fetch.h"
#include "simulated_device.h"
#include "wait_for.h"

namespace {

namespace fs = std::filesystem;
using namespace wircam::testing;
using namespace std::chrono_literals;

// A UDP socket of the test's own on loopback: where a misdirected stream
// lands.
struct Elsewhere {
  wircam::UniqueFd socket;
  Elsewhere() {
    auto bound = wircam::bindUdp(wircam::SocketAddress::loopback(0));
    if (bound) socket = std::move(*bound);
  }
  uint16_t port() const { return wircam::localAddress(socket.get()).port(); }
  // Whether a datagram arrives within `timeout`.
  bool receives(std::chrono::milliseconds timeout) const {
    pollfd ready{.fd = socket.get(), .events = POLLIN};
    return poll(&ready, 1, static_cast<int>(patience(timeout).count())) == 1;
  }
};

TEST(CameraFaults, ACameraWhoseDatagramsGoElsewhereIsNoVideoWhileTheOtherRecords) {
  auto good = startSequenceDevice();
  ASSERT_TRUE(good);
  Elsewhere elsewhere;
  ASSERT_TRUE(elsewhere.socket.valid());
  auto lost = startSequenceDevice(0, 15, {.misdirectPort = elsewhere.port()});
  ASSERT_TRUE(lost);
  RecorderProcess recorder(good->port(), {"--device", "127.0.0.1:" + std::to_string(lost->port()),
                                          "--stall-timeout", "1", "--http", "127.0.0.1:0"});
  auto url = recorder.waitForLog("http://", 5000ms);
  ASSERT_TRUE(url) << recorder.log();
  // The device does stream: to the wrong port.
  EXPECT_TRUE(elsewhere.receives(5000ms));
  std::string lostName = cameraName(lost->port()), goodName = cameraName(good->port());
  // Two seconds of the good camera's frames, while the other, logged in
  // and streaming nowhere it can hear, is no-video and started again.
  EXPECT_TRUE(waitFor([&] { return framesOf(*url, goodName) >= 30; }, 10s)) << recorder.log();
  EXPECT_TRUE(waitFor(
      [&] {
        auto entry = streamEntry(*url, lostName);
        return entry["state"] == "no-video" && entry["restarts"].get<int>() >= 1;
      },
      10s))
      << streamEntry(*url, lostName) << recorder.log();
  EXPECT_EQ(cameraEntry(*url, goodName)["state"], "live");
  expectSigintEndsItWithinThreeSeconds(recorder);
  // Every frame received before the stop is in the file.
  EXPECT_GE(indexedFrames(recorder.out(), goodName), 30u) << recorder.log();
  EXPECT_EQ(indexedFrames(recorder.out(), lostName), 0u);
  auto videos = recorder.files(".mkv");
  ASSERT_EQ(videos.size(), 1u);
  EXPECT_GT(durationOf(videos[0]), GST_SECOND);
}

// "20261122T143205Z": the UTC second in the recorder's file names (written
// here again: the test reads the names as a user would, not through the
// recorder's code).
std::string fileTime(int64_t unixMs) {
  time_t seconds = static_cast<time_t>(unixMs / 1000);
  std::tm tm{};
  gmtime_r(&seconds, &tm);
  char text[32];
  std::strftime(text, sizeof text, "%Y%m%dT%H%M%SZ", &tm);
  return text;
}

// Every name a camera's files could take in the seconds [from, to) (wall
// clock) made a dangling link into a folder that does not exist: opening
// any of them for writing fails, as a broken disk would.
void breakFileNames(const fs::path& out, const std::string& camera, int64_t fromUnixMs,
                    int64_t toUnixMs) {
  for (int64_t ms = fromUnixMs; ms < toUnixMs; ms += 1000) {
    auto name = out / (camera + "-" + fileTime(ms) + ".mkv");
    std::error_code exists;
    if (!fs::exists(fs::symlink_status(name, exists)))
      fs::create_symlink("/nonexistent-wircam-disk/file.mkv", name);
  }
}

int64_t unixMsNow() {
  return std::chrono::duration_cast<std::chrono::milliseconds>(
             std::chrono::system_clock::now().time_since_epoch())
      .count();
}

TEST(CameraFaults, AnErrorOnOneCamerasFileRestartsThatCameraAloneAndItRecordsAgain) {
  auto good = startSequenceDevice();
  auto broken = startSequenceDevice();
  ASSERT_TRUE(good && broken);
  RecorderProcess recorder(good->port(), {"--device", "127.0.0.1:" + std::to_string(broken->port()),
                                          "--segment", "2", "--http", "127.0.0.1:0"});
  auto url = recorder.waitForLog("http://", 5000ms);
  ASSERT_TRUE(url) << recorder.log();
  std::string brokenName = cameraName(broken->port()), goodName = cameraName(good->port());
  // Once its first file is open, its next files' names (from the cut 2 s
  // on, for 3 s) cannot be written.
  ASSERT_TRUE(waitFor([&] { return streamEntry(*url, brokenName)["segment"] != ""; }, 10s))
      << recorder.log();
  int64_t firstOpen = unixMsNow();
  breakFileNames(recorder.out(), brokenName, firstOpen + 1000, firstOpen + 4000);
  // Its pipeline fails on the next file, is torn down and started again.
  ASSERT_TRUE(waitFor(
      [&] {
        auto entry = streamEntry(*url, brokenName);
        return !entry.is_null() && entry["restarts"].get<int>() >= 1;
      },
      10s))
      << recorder.log();
  EXPECT_NE(recorder.log().find(brokenName + ": restarting its pipeline after the error above"),
            std::string::npos)
      << recorder.log();
  EXPECT_EQ(cameraEntry(*url, goodName)["state"], "live");
  // Past the broken names it records again, into a file of its own.
  auto recordedAgain = [&] {
    for (const auto& video : recorder.files(".mkv"))
      if (video.filename().string().starts_with(brokenName) && !fs::is_symlink(video) &&
          video.filename().string() > brokenName + "-" + fileTime(firstOpen + 4000))
        return fs::file_size(video) > 50'000;
    return false;
  };
  EXPECT_TRUE(waitFor(recordedAgain, 15s)) << recorder.log();
  uint64_t goodBefore = indexedFrames(recorder.out(), goodName);

  expectSigintEndsItWithinThreeSeconds(recorder);
  // The good camera recorded on throughout: 15 fps in 2 s files.
  EXPECT_GT(indexedFrames(recorder.out(), goodName), goodBefore);
  EXPECT_GT(indexedFrames(recorder.out(), brokenName), 15u);
  for (const auto& video : recorder.files(".mkv"))
    if (!fs::is_symlink(video)) {
      EXPECT_TRUE(GST_CLOCK_TIME_IS_VALID(durationOf(video))) << video;
    }
}

TEST(CameraFaults, ADeviceRestartingDuringTheStopHoldsNothingUp) {
  auto steady = startSequenceDevice();
  auto restarting = startSequenceDevice();
  ASSERT_TRUE(steady && restarting);
  uint16_t port = restarting->port();
  RecorderProcess recorder(steady->port(), {"--device", "127.0.0.1:" + std::to_string(port)});
  ASSERT_TRUE(waitFor(
      [&] {
        auto videos = recorder.files(".mkv");
        return videos.size() == 2 && fs::file_size(videos[0]) > 50'000 &&
               fs::file_size(videos[1]) > 50'000;
      },
      10s))
      << recorder.log();
  // Gone mid-stop, and back a moment later: a new login answers the
  // recorder's, with frames, while it is finishing.
  expectSigintEndsItWithinThreeSeconds(recorder, [&] {
    HeldPort off = switchOff(restarting);
    restarting = switchOn(off);
  });
  ASSERT_TRUE(restarting);
  EXPECT_GT(indexedFrames(recorder.out(), cameraName(steady->port())), 0u) << recorder.log();
  EXPECT_GT(indexedFrames(recorder.out(), cameraName(port)), 0u) << recorder.log();
  for (const auto& video : recorder.files(".mkv")) {
    EXPECT_TRUE(GST_CLOCK_TIME_IS_VALID(durationOf(video))) << video;
  }
}

// /api/status's streams that have recorded at least `frames`.
int streamsWithFrames(const std::string& url, int frames) {
  auto status = nlohmann::json::parse(fetch(url + "api/status").body, nullptr, false);
  int count = 0;
  if (status.is_object())
    for (const auto& stream : status["streams"]) count += stream["frames"].get<int>() >= frames;
  return count;
}

TEST(CameraFaults, TwoHundredDevicesOfWhichTwentyNeverAnswer) {
  constexpr int kDevices = 200, kSilent = 20, kAnswering = kDevices - kSilent;
  // 5 fps keeps 180 senders and the recorder within a loaded CI machine.
  std::vector<std::unique_ptr<wircam::wirc::Device>> devices;
  std::vector<SilentPeer> silent(kSilent);
  std::vector<std::string> arguments = {"--http", "127.0.0.1:0"};
  for (int i = 0; i < kAnswering; ++i) {
    devices.push_back(startSequenceDevice(0, 5));
    ASSERT_TRUE(devices.back());
    if (i > 0)  // the first is the recorder process's own
      arguments.insert(arguments.end(),
                       {"--device", "127.0.0.1:" + std::to_string(devices.back()->port())});
  }
  for (const auto& peer : silent)
    arguments.insert(arguments.end(), {"--device", "127.0.0.1:" + std::to_string(peer.port())});
  RecorderProcess recorder(devices[0]->port(), arguments);
  auto url = recorder.waitForLog("http://", 10000ms);
  ASSERT_TRUE(url) << recorder.log();
  // Every answering device's camera records a second (5 frames).
  EXPECT_TRUE(waitFor([&] { return streamsWithFrames(*url, 5) == kAnswering; }, 30s))
      << streamsWithFrames(*url, 5) << " recording" << recorder.log();
  for (const auto& peer : silent) {
    EXPECT_EQ(cameraEntry(*url, cameraName(peer.port()))["state"], "connecting");
  }
  expectSigintEndsItWithinThreeSeconds(recorder);
  int indexed = 0;
  for (const auto& device : devices)
    indexed += indexedFrames(recorder.out(), cameraName(device->port())) > 0;
  EXPECT_EQ(indexed, kAnswering) << recorder.log();
  int playable = 0;
  for (const auto& video : recorder.files(".mkv"))
    playable += GST_CLOCK_TIME_IS_VALID(durationOf(video));
  EXPECT_EQ(playable, kAnswering);
}

}  // namespace
