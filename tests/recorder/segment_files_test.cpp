// Recordings people can trust, checked with ffprobe and ffmpeg on the real
// files: each segment starts at 0 on a key frame and decodes whole, has the
// length asked for, is named by its UTC start, has a sidecar on its own
// timeline, holds no gap from an outage, and a recorder started before its
// device waits for it.
#include <gtest/gtest.h>
#include <signal.h>

#include <algorithm>
#include <cstdio>
#include <ctime>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <thread>

#include "camera_checks.h"
#include "http_fetch.h"
#include "recorder_process.h"
#include "shell_command.h"
#include "simulated_device.h"
#include "wait_for.h"

namespace {

namespace fs = std::filesystem;
using namespace wircam;
using namespace wircam::testing;
using std::chrono::milliseconds;

struct ProbedFrame {
  bool key;
  double pts;
};

// The video frames as ffprobe decodes them, in presentation order.
std::vector<ProbedFrame> probeFrames(const fs::path& file) {
  std::istringstream csv(
      commandOutput("ffprobe -v error -select_streams v:0 -show_frames -show_entries "
                    "frame=key_frame,pts_time -of csv=p=0 '" +
                    file.string() + "'"));
  std::vector<ProbedFrame> frames;
  for (std::string line; std::getline(csv, line);) {
    int key = 0;
    double pts = 0;
    if (std::sscanf(line.c_str(), "%d,%lf", &key, &pts) == 2) frames.push_back({key == 1, pts});
  }
  return frames;
}

double probeDuration(const fs::path& file) {
  return std::stod("0" +
                   commandOutput("ffprobe -v error -show_entries format=duration -of csv=p=0 '" +
                                 file.string() + "'"));
}

int probePackets(const fs::path& file) {
  return std::stoi(
      "0" + commandOutput("ffprobe -v error -select_streams v:0 -count_packets -show_entries "
                          "stream=nb_read_packets -of csv=p=0 '" +
                          file.string() + "'"));
}

// "rover-cam0-20261122T143205Z.mkv" → seconds since the epoch.
std::optional<std::time_t> utcOfName(const std::string& name) {
  auto at = name.rfind("-20");
  std::tm tm{};
  if (at == std::string::npos ||
      std::sscanf(name.c_str() + at + 1, "%4d%2d%2dT%2d%2d%2dZ", &tm.tm_year, &tm.tm_mon,
                  &tm.tm_mday, &tm.tm_hour, &tm.tm_min, &tm.tm_sec) != 6)
    return std::nullopt;
  tm.tm_year -= 1900;
  tm.tm_mon -= 1;
  return timegm(&tm);
}

std::vector<nlohmann::json> sidecarOf(const fs::path& video) {
  std::ifstream in(fs::path(video).replace_extension(".jsonl"));
  std::vector<nlohmann::json> lines;
  for (std::string line; std::getline(in, line);) lines.push_back(nlohmann::json::parse(line));
  return lines;
}

struct Format {
  const char* codec;
  const char* container;
};
// Printed as codec_container: CTest names each test by it (.../jpeg_mkv).
// Printed as bytes (pointers, other in every run) or with spaces, the name
// had no cost data: CTest never knew its time and started it last.
void PrintTo(const Format& format, std::ostream* out) {
  *out << format.codec << "_" << format.container;
}

class SegmentFiles : public ::testing::TestWithParam<Format> {};

TEST_P(SegmentFiles, EachStartsAtZeroOnAKeyFrameDecodesWholeAndLastsItsLength) {
  auto [codec, container] = GetParam();
  auto device = startSequenceDevice();
  std::time_t launched = std::time(nullptr);
  // 2 s segments: each holds at least one of the once-a-second statistics.
  // 7 s from the launch: three files even if the login takes 2 s.
  RecorderProcess recorder(device->port(), {"--segment", "2", "--duration", "7", "--codec", codec,
                                            "--format", container});
  ASSERT_EQ(recorder.wait(), 0) << recorder.log();
  auto videos = recorder.files(std::string(".") + container);
  ASSERT_GE(videos.size(), 3u);
  std::time_t expectedStart = launched;
  for (size_t i = 0; i < videos.size(); ++i) {
    const auto& video = videos[i];
    SCOPED_TRACE(video.filename().string());
    bool last = i + 1 == videos.size();
    auto frames = probeFrames(video);
    // The last file runs from its cut to the stop, however short that is.
    // (A device this machine starved for seconds skips its frames: a file
    // then holds a gap, and the device says how long it was held.)
    ASSERT_GT(frames.size(), last ? 0u : 10u)
        << "the device's longest wait between frames: " << device->stats().maxTickGap.count()
        << " ms";
    EXPECT_TRUE(frames.front().key);
    EXPECT_LT(frames.front().pts, 0.1);
    // Every packet decodes to a frame, without a word from the decoder.
    EXPECT_EQ(static_cast<int>(frames.size()), probePackets(video));
    EXPECT_EQ(ffmpegDecodeErrors(video), "");
    double duration = probeDuration(video);
    // The last ends when the recording does: what its stop let through
    // stays in it (no file of a frame or two).
    if (last) {
      EXPECT_LE(duration, 3.0);
    } else {
      EXPECT_NEAR(duration, 2.0, 0.5);
    }
    // Named by the wall clock time of its first frame: the first once the
    // recorder has started and logged in (seconds on a loaded machine), each
    // next one where the one before ended.
    auto named = utcOfName(video.filename().string());
    ASSERT_TRUE(named);
    if (i == 0) {
      EXPECT_GE(*named, launched - 1);
      EXPECT_LE(*named, launched + 10);
    } else {
      EXPECT_NEAR(static_cast<double>(*named), static_cast<double>(expectedStart), 1.5);
    }
    expectedStart = *named + static_cast<std::time_t>(duration + 0.5);
    // The telemetry track is named, and players do not show it by default.
    EXPECT_EQ(commandOutput("ffprobe -v error -select_streams s:0 -show_entries "
                            "stream_disposition=default,forced:stream_tags=title -of csv=p=0 '" +
                            video.string() + "'"),
              std::string(container) == "mkv" ? "0,0,telemetry\n" : "0,0\n");
    // Its sidecar is on its own timeline, every line within the file. (The
    // last file ends with the recording, and may end before a statistics
    // line comes.)
    auto lines = sidecarOf(video);
    if (!last) {
      ASSERT_FALSE(lines.empty());
    }
    for (const auto& line : lines) {
      ASSERT_TRUE(line.contains("pts") && line.contains("utc")) << line;
      EXPECT_LE(line["pts"].get<double>() / 1e9, duration + 0.1) << line;
      EXPECT_EQ(line["utc"].get<std::string>().back(), 'Z') << line;
    }
  }
  // The login is in the first segment, in the sidecar and in the file.
  std::string sidecar, track;
  for (const auto& line : sidecarOf(videos[0])) sidecar += line.dump();
  for (const auto& line : contentsOf(videos[0]).telemetry) track += line;
  EXPECT_NE(sidecar.find("logged in"), std::string::npos);
  EXPECT_NE(track.find("logged in"), std::string::npos);
}

INSTANTIATE_TEST_SUITE_P(Formats, SegmentFiles,
                         ::testing::Values(Format{"jpeg", "mkv"}, Format{"h264", "mkv"},
                                           Format{"h264", "mp4"}));

TEST(SegmentFilesSidecarOnly, WithTheTelemetryTrackOffAFileIsItsFramesAndTheSidecarKeepsAll) {
  auto device = startSequenceDevice();
  RecorderProcess recorder(device->port(),
                           {"--segment", "2", "--duration", "5", "--telemetry-track", "off"});
  ASSERT_EQ(recorder.wait(), 0) << recorder.log();
  auto videos = recorder.files(".mkv");
  ASSERT_GE(videos.size(), 2u);
  auto index = nlohmann::json::parse(std::ifstream(recorder.out() / "index.json"));
  ASSERT_EQ(index["segments"].size(), videos.size()) << index;
  for (const auto& video : videos) {
    SCOPED_TRACE(video.filename().string());
    bool last = video == videos.back();
    EXPECT_EQ(commandOutput("ffprobe -v error -show_entries stream=codec_type -of csv=p=0 '" +
                            video.string() + "'"),
              "video\n");
    EXPECT_EQ(ffmpegDecodeErrors(video), "");
    auto frames = probeFrames(video);
    // (The last file runs from its cut to the stop, however short. A
    // device this machine starved for seconds skips its frames: a file
    // then holds a gap, and the device says how long it was held.)
    ASSERT_GT(frames.size(), last ? 0u : 10u)
        << "the device's longest wait between frames: " << device->stats().maxTickGap.count()
        << " ms";
    EXPECT_TRUE(frames.front().key);
    EXPECT_LT(frames.front().pts, 0.1);
    for (const auto& segment : index["segments"]) {
      if (segment["file"] == video.filename().string()) {
        EXPECT_EQ(segment["frames"], static_cast<int>(frames.size())) << segment;
      }
    }
    if (!last) {
      EXPECT_FALSE(sidecarOf(video).empty());  // (the last may end before a line)
    }
  }
  std::string sidecar;
  for (const auto& line : sidecarOf(videos[0])) sidecar += line.dump();
  EXPECT_NE(sidecar.find("logged in"), std::string::npos);
  EXPECT_NE(sidecar.find("\"stats\""), std::string::npos);
}

TEST(SegmentFilesOutage, ADeviceLossEndsTheFileAndNoFileHoldsAGap) {
  auto device = startSequenceDevice();
  uint16_t port = device->port();
  RecorderProcess recorder(port, {"--segment", "60", "--http", "127.0.0.1:0"});
  auto url = recorder.waitForLog("http://", milliseconds(5000));
  ASSERT_TRUE(url) << recorder.log();
  ASSERT_TRUE(waitFor([&] { return framesOf(*url, cameraName(port)) >= 30; }, milliseconds(10000)))
      << recorder.log();
  HeldPort off = switchOff(device);
  // The device stays off while the recorder backs off (200 + 400 + 800 +
  // 1600 ms): the outage the loss line's own time must show.
  ASSERT_TRUE(recorder.waitForText("retrying in 1600 ms", milliseconds(10000))) << recorder.log();
  device = switchOn(off);
  ASSERT_TRUE(device);
  // The second file: a second and a half of frames.
  ASSERT_TRUE(waitFor([&] { return recorder.files(".mkv").size() == 2; }, milliseconds(10000)));
  uint64_t back = framesOf(*url, cameraName(port));
  ASSERT_TRUE(
      waitFor([&] { return framesOf(*url, cameraName(port)) >= back + 22; }, milliseconds(10000)))
      << recorder.log();
  recorder.signal(SIGINT);
  ASSERT_EQ(recorder.wait(), 0) << recorder.log();
  auto videos = recorder.files(".mkv");
  ASSERT_EQ(videos.size(), 2u);
  constexpr double kFramePeriod = 1.0 / 15;
  for (const auto& video : videos) {
    auto frames = probeFrames(video);
    ASSERT_GT(frames.size(), 15u) << video;
    double widest = 0;
    for (size_t i = 1; i < frames.size(); ++i)
      widest = std::max(widest, frames[i].pts - frames[i - 1].pts);
    EXPECT_LE(widest, 0.5) << video;
    // Nothing in the file, its telemetry track included, runs on past its
    // last frame (a player would show a frozen picture for the outage).
    double lastFrame = frames.back().pts;
    EXPECT_LE(probeDuration(video), lastFrame + kFramePeriod + 0.002) << video;
    for (const auto& line : sidecarOf(video))
      EXPECT_LE(line["pts"].get<double>() / 1e9, lastFrame + kFramePeriod) << video << line;
  }
  // The loss and the retries came between the files: they open the next
  // file's sidecar, at pts 0 with their own time, as the login does.
  auto second = sidecarOf(videos[1]);
  auto loss = std::find_if(second.begin(), second.end(), [](const auto& line) {
    return line.dump().find("link lost: the device closed the connection") != std::string::npos;
  });
  ASSERT_NE(loss, second.end());
  EXPECT_EQ((*loss)["pts"], 0);
  // Its own time: about 5 s before that file's first frame.
  std::tm lost{};
  std::string lostUtc = (*loss)["utc"];
  ASSERT_EQ(std::sscanf(lostUtc.c_str(), "%4d-%2d-%2dT%2d:%2d:%2d", &lost.tm_year, &lost.tm_mon,
                        &lost.tm_mday, &lost.tm_hour, &lost.tm_min, &lost.tm_sec),
            6);
  lost.tm_year -= 1900;
  lost.tm_mon -= 1;
  EXPECT_LT(timegm(&lost), *utcOfName(videos[1].filename().string()) - 2) << lostUtc;
  for (const auto& line : sidecarOf(videos[0]))
    EXPECT_EQ(line.dump().find("link lost"), std::string::npos) << line;
}

TEST(SegmentFilesStartUp, ARecorderStartedBeforeItsDeviceWaitsAndThenRecords) {
  auto probe = startSequenceDevice();
  HeldPort off = switchOff(probe);
  uint16_t port = off.port();
  RecorderProcess recorder(port, {"--segment", "60", "--http", "127.0.0.1:0"});
  auto url = recorder.waitForLog("http://", milliseconds(5000));
  ASSERT_TRUE(url) << recorder.log();
  // Login attempts fail meanwhile.
  ASSERT_TRUE(recorder.waitForText("retrying in 400 ms", milliseconds(10000))) << recorder.log();
  ASSERT_TRUE(waitFor(
      [&] { return recorder.statusLines().find("waiting for device") != std::string::npos; },
      milliseconds(5000)));
  auto status = nlohmann::json::parse(fetch(*url + "api/status").body);
  EXPECT_EQ(status["streams"][0]["state"], "connecting") << status;
  auto device = switchOn(off);
  ASSERT_TRUE(device);
  // The backoff, then two seconds of frames.
  ASSERT_TRUE(waitFor([&] { return framesOf(*url, cameraName(port)) >= 30; }, milliseconds(15000)))
      << recorder.log();
  status = nlohmann::json::parse(fetch(*url + "api/status").body);
  EXPECT_EQ(status["streams"][0]["state"], "live") << status;
  recorder.signal(SIGTERM);
  ASSERT_EQ(recorder.wait(), 0) << recorder.log();
  auto videos = recorder.files(".mkv");
  ASSERT_EQ(videos.size(), 1u);
  EXPECT_GT(probeFrames(videos[0]).size(), 15u);
}

TEST(SegmentFilesStartUp, StoppedWhileWaitingItEndsCleanly) {
  auto probe = startSequenceDevice();
  HeldPort off = switchOff(probe);
  RecorderProcess recorder(off.port(), {"--segment", "60"});
  ASSERT_TRUE(recorder.waitForText("retrying in 400 ms", milliseconds(10000))) << recorder.log();
  recorder.signal(SIGTERM);
  EXPECT_EQ(recorder.wait(), 0) << recorder.log();
  EXPECT_NE(recorder.log().find("nothing was recorded"), std::string::npos) << recorder.log();
}

}  // namespace
