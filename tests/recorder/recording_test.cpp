// What wirc-recorder writes: segments that play, every frame in order, the
// telemetry in the file and beside it, and the files finished whatever
// happens (SIGINT, kill -9, the device going away).
#include <gtest/gtest.h>
#include <signal.h>

#include <fstream>
#include <nlohmann/json.hpp>
#include <set>
#include <sstream>
#include <thread>

#include "http_fetch.h"
#include "recorder_process.h"
#include "simulated_device.h"
#include "wait_for.h"

namespace {

namespace fs = std::filesystem;
using namespace wircam;
using namespace wircam::testing;
using std::chrono::milliseconds;

std::vector<std::string> linesOf(const fs::path& file) {
  std::ifstream in(file);
  std::vector<std::string> lines;
  for (std::string line; std::getline(in, line);) lines.push_back(line);
  return lines;
}

TEST(WircRecorder, RecordsPlayableSegmentsWithTelemetry) {
  auto device = startSequenceDevice();
  RecorderProcess recorder(device->port(), {"--segment", "2", "--duration", "5"});
  ASSERT_EQ(recorder.wait(), 0) << recorder.log();
  auto videos = recorder.files(".mkv");
  ASSERT_GE(videos.size(), 2u);
  GstClockTime total = 0;
  for (const auto& video : videos) {
    GstClockTime duration = durationOf(video);
    ASSERT_TRUE(GST_CLOCK_TIME_IS_VALID(duration)) << video;
    total += duration;
    ASSERT_TRUE(fs::exists(fs::path(video).replace_extension(".jsonl"))) << video;
  }
  // About the 5 s asked for, less the start-up before the first frame.
  EXPECT_GT(total, 3 * GST_SECOND);
  EXPECT_LT(total, 6 * GST_SECOND);
  bool stats = false;
  for (const auto& line : linesOf(recorder.files(".jsonl")[0]))
    stats = stats || nlohmann::json::parse(line)["type"] == "stats";
  EXPECT_TRUE(stats);
}

TEST(WircRecorder, RecordsEveryFrameDeliveredInOrder) {
  auto device = startSequenceDevice();
  RecorderProcess recorder(device->port(), {"--segment", "2", "--duration", "5"});
  ASSERT_EQ(recorder.wait(), 0) << recorder.log();
  // The device's count is final once the stream is stopped.
  ASSERT_TRUE(waitFor([&] { return device->stats().activeStreams == 0; }, milliseconds(2000)));
  uint64_t sent = device->stats().framesSent;  // to this receiver, none lost on loopback
  int recorded = 0;
  constexpr GstClockTime kFramePeriod = GST_SECOND / 15;
  for (const auto& video : recorder.files(".mkv")) {
    auto contents = contentsOf(video);
    EXPECT_TRUE(contents.monotonic) << video;
    EXPECT_EQ(contents.videoCaps, "image/jpeg");
    // The file says it lasts as long as its frames span, and they span
    // their number of frame periods (no gap), each to within one period.
    // (The last may hold a single frame: a stop just after a cut.)
    ASSERT_GT(contents.frames, 0);
    auto period = static_cast<GstClockTimeDiff>(kFramePeriod);
    auto duration = static_cast<GstClockTimeDiff>(durationOf(video));
    auto span = static_cast<GstClockTimeDiff>(contents.framePts.back() - contents.framePts.front());
    EXPECT_LE(std::abs(duration - span), period) << video;
    EXPECT_LE(std::abs(span - (contents.frames - 1) * period), period) << video;
    recorded += contents.frames;
  }
  ASSERT_GT(sent, 40u);
  // The frame in flight when the stream stopped may be missing.
  EXPECT_LE(static_cast<uint64_t>(recorded), sent);
  EXPECT_GE(static_cast<uint64_t>(recorded) + 2, sent);
  // The last status line, printed once the camera has stopped, counts
  // every frame received, not those of the source's last once-a-second
  // report.
  std::istringstream lines(recorder.statusLines());
  unsigned long long counted = 0;
  for (std::string line; std::getline(lines, line);) {
    unsigned long long frames = 0;
    char word[16] = {};
    if (std::sscanf(line.c_str(), "%*s %llu %15s", &frames, word) == 2 &&
        std::string(word) == "frames")
      counted = frames;
  }
  EXPECT_GE(counted, static_cast<unsigned long long>(recorded)) << recorder.statusLines();
  EXPECT_LE(counted, sent);
}

TEST(WircRecorder, TheFileCarriesTheTelemetryAsATextTrack) {
  auto device = startFollowDevice();
  ASSERT_TRUE(device);
  RecorderProcess recorder(device->port(),
                           {"--segment", "2", "--duration", "5", "--detect", "tag36h11"});
  ASSERT_EQ(recorder.wait(), 0) << recorder.log();
  std::multiset<std::string> sidecar, track;
  int detections = 0, onAFrame = 0;
  for (const auto& video : recorder.files(".mkv")) {
    for (const auto& line : linesOf(fs::path(video).replace_extension(".jsonl")))
      sidecar.insert(line);
    auto contents = contentsOf(video);
    std::set<GstClockTime> frames;  // Matroska keeps milliseconds
    for (GstClockTime pts : contents.framePts) frames.insert(pts / GST_MSECOND);
    for (const auto& line : contents.telemetry) {
      track.insert(line);
      auto event = nlohmann::json::parse(line);
      if (event["type"] != "detections") continue;
      ++detections;
      // A detection's pts is the time of the frame it was found in.
      GstClockTime ms = event["pts"].get<GstClockTime>() / GST_MSECOND;
      onAFrame += frames.count(ms) || frames.count(ms + 1);  // rounded to the nearest
    }
  }
  // The sidecars also hold what came after the end of the stream.
  for (const auto& line : track) EXPECT_TRUE(sidecar.count(line)) << line;
  EXPECT_GT(track.size(), sidecar.size() * 8 / 10);
  EXPECT_GT(detections, 30);
  EXPECT_GE(onAFrame, detections - 2);  // the frames in flight at a cut
}

TEST(WircRecorder, TranscodesToH264InFragmentedMp4) {
  auto device = startSequenceDevice();
  RecorderProcess recorder(
      device->port(), {"--segment", "2", "--duration", "5", "--codec", "h264", "--format", "mp4"});
  ASSERT_EQ(recorder.wait(), 0) << recorder.log();
  auto videos = recorder.files(".mp4");
  ASSERT_GE(videos.size(), 2u);
  int frames = 0;
  for (const auto& video : videos) {
    EXPECT_TRUE(GST_CLOCK_TIME_IS_VALID(durationOf(video))) << video;
    auto contents = contentsOf(video);
    EXPECT_EQ(contents.videoCaps, "video/x-h264");
    EXPECT_TRUE(contents.monotonic);
    EXPECT_TRUE(fs::exists(fs::path(video).replace_extension(".jsonl")));
    frames += contents.frames;
  }
  uint64_t sent = device->stats().framesSent;
  EXPECT_GE(static_cast<uint64_t>(frames) + 3, sent);
}

TEST(WircRecorder, RefusesMp4WithoutTranscoding) {
  RecorderProcess recorder(0, {"--out", "/tmp", "--format", "mp4"});
  EXPECT_EQ(recorder.wait(), 2);
  EXPECT_NE(recorder.log().find("--codec h264"), std::string::npos) << recorder.log();
}

TEST(WircRecorder, SigintFinishesEveryFileAndExitsZero) {
  auto device = startSequenceDevice();
  RecorderProcess recorder(device->port(), {"--segment", "60"});
  // Two seconds of frames on their way into the file.
  ASSERT_TRUE(waitFor([&] { return device->stats().framesSent >= 30; }, milliseconds(10000)));
  ASSERT_TRUE(waitFor([&] { return recorder.files(".mkv").size() == 1; }, milliseconds(5000)));
  recorder.signal(SIGINT);
  ASSERT_EQ(recorder.wait(), 0) << recorder.log();
  auto videos = recorder.files(".mkv");
  ASSERT_EQ(videos.size(), 1u);
  GstClockTime duration = durationOf(videos[0]);
  ASSERT_TRUE(GST_CLOCK_TIME_IS_VALID(duration));
  EXPECT_GT(duration, GST_SECOND);
}

// What a crash costs: the frames the device sent that are not in the file.
// Clusters (Matroska) and fragments (MP4) of 1 s, and the one GOP
// the muxer is writing, lose at most 1.5 s.
void expectPlayableAfterKill9(const std::vector<std::string>& options, const char* extension) {
  auto device = startSequenceDevice();
  RecorderProcess recorder(device->port(), options);
  // Four seconds of frames: clusters or fragments written, one under way.
  ASSERT_TRUE(waitFor([&] { return device->stats().framesSent >= 60; }, milliseconds(15000)));
  recorder.signal(SIGKILL);
  recorder.wait();
  uint64_t sent = device->stats().framesSent;
  auto videos = recorder.files(extension);
  ASSERT_EQ(videos.size(), 1u);
  auto contents = contentsOf(videos[0]);
  EXPECT_TRUE(contents.monotonic);
  constexpr int kFps = 15;
  EXPECT_GE(static_cast<uint64_t>(contents.frames) + kFps * 3 / 2, sent)
      << contents.frames << " of " << sent << " frames";
}

TEST(WircRecorder, AfterKill9TheOpenMatroskaSegmentLosesAtMostASecondAndAHalf) {
  expectPlayableAfterKill9({"--segment", "60"}, ".mkv");
}

TEST(WircRecorder, AfterKill9TheOpenMp4SegmentLosesAtMostASecondAndAHalf) {
  expectPlayableAfterKill9({"--segment", "60", "--codec", "h264", "--format", "mp4"}, ".mp4");
}

TEST(WircRecorder, DeletesTheOldestSegmentsToStayUnderMaxBytes) {
  auto device = startSequenceDevice();
  RecorderProcess recorder(device->port(),
                           {"--segment", "1", "--duration", "6", "--max-bytes", "400K"});
  ASSERT_EQ(recorder.wait(), 0) << recorder.log();
  uint64_t total = 0, largest = 0;
  for (const auto& entry : fs::directory_iterator(recorder.out())) {
    total += entry.file_size();
    largest = std::max<uint64_t>(largest, entry.file_size());
  }
  auto videos = recorder.files(".mkv");
  ASSERT_FALSE(videos.empty());
  EXPECT_LT(videos.size(), 5u);  // about 6 one-second segments were made
  // Checked when a segment closes: at most the newest one beyond the cap.
  EXPECT_LE(total, 400000 + 2 * largest);
  // The oldest went first: what was deleted is older than what is left
  // (names carry the UTC start), and the index lists only what is left.
  auto log = recorder.log();
  auto at = log.find("deleted ");
  ASSERT_NE(at, std::string::npos) << log;
  std::string firstDeleted = log.substr(at + 8, log.find(' ', at + 8) - at - 8);
  EXPECT_LT(firstDeleted, videos.front().filename().string());
  std::ifstream indexFile(recorder.out() / "index.json");
  auto index = nlohmann::json::parse(indexFile);
  ASSERT_EQ(index["segments"].size(), videos.size());
  for (size_t i = 0; i < videos.size(); ++i)
    EXPECT_EQ(index["segments"][i]["file"], videos[i].filename().string());
  for (const auto& video : videos)
    EXPECT_TRUE(fs::exists(fs::path(video).replace_extension(".jsonl")));
}

TEST(WircRecorder, DeletesSegmentsOlderThanMaxAgeButKeepsThoseWithEventsLonger) {
  auto device = startSequenceDevice();
  RecorderProcess first(device->port(), {"--segment", "1", "--duration", "2.5"});
  ASSERT_EQ(first.wait(), 0) << first.log();
  auto made = first.files(".mkv");
  ASSERT_FALSE(made.empty());
  // Back-dated copies in the folder of a second run: a quiet one and one
  // with a tag seen, both ten days old, and a recent one.
  fs::path out = first.out().parent_path() / "aged";
  fs::create_directories(out);
  std::string camera = "127.0.0.1-" + std::to_string(device->port()) + "-cam0";
  auto place = [&](const std::string& time, int daysAgo, const std::string& extraLine) {
    fs::path video = out / (camera + "-" + time + ".mkv");
    fs::copy(made.front(), video);
    fs::copy(fs::path(made.front()).replace_extension(".jsonl"),
             fs::path(video).replace_extension(".jsonl"));
    std::ofstream(fs::path(video).replace_extension(".jsonl"), std::ios::app) << extraLine;
    fs::last_write_time(video, fs::file_time_type::clock::now() - std::chrono::hours(24 * daysAgo));
    return video;
  };
  auto quiet = place("20261101T000000Z", 10, "");
  auto tagged = place("20261101T000100Z", 10,
                      R"({"type":"detections","detections":[{"id":0}],"pts":1000})"
                      "\n");
  auto recent = place("20261101T000200Z", 0, "");
  RecorderProcess second(
      0, {"--device", "127.0.0.1:" + std::to_string(device->port()), "--out", out.string(),
          "--max-age", "1d", "--keep-events", "30d", "--http", "127.0.0.1:0", "--duration", "30"});
  auto url = second.waitForLog("http://", milliseconds(10000));
  ASSERT_TRUE(url) << second.log();
  EXPECT_TRUE(second.waitForText("deleted " + quiet.filename().string() + " (older than --max-age)",
                                 milliseconds(10000)))
      << second.log();
  EXPECT_FALSE(fs::exists(quiet));
  EXPECT_TRUE(fs::exists(tagged));
  EXPECT_TRUE(fs::exists(recent));
  auto status = nlohmann::json::parse(fetch(*url + "api/status").body);
  EXPECT_EQ(status["retention"]["max_age_s"], 86400);
  EXPECT_EQ(status["retention"]["keep_events_s"], 30 * 86400);
  second.signal(SIGINT);
  EXPECT_EQ(second.wait(), 0) << second.log();
  auto index = nlohmann::json::parse(std::ifstream(out / "index.json"));
  for (const auto& entry : index["segments"]) EXPECT_NE(entry["file"], quiet.filename().string());
}

TEST(WircRecorder, TakesItsDevicesFromAConfigFile) {
  auto device = startSequenceDevice();
  auto folder = fs::temp_directory_path() / ("wirc-recorder-config-" + std::to_string(getpid()));
  fs::remove_all(folder);
  fs::create_directories(folder);
  auto config = folder / "recorder.ini";
  std::ofstream(config) << "[recorder]\nout=" << (folder / "out").string()
                        << "\nsegment=60\n\n[device rover]\nhost=127.0.0.1\nport=" << device->port()
                        << "\ncameras=0\n";
  RecorderProcess recorder(0, {"--config", config.string(), "--duration", "3"});
  ASSERT_EQ(recorder.wait(), 0) << recorder.log();
  std::vector<fs::path> videos;
  for (const auto& entry : fs::directory_iterator(folder / "out"))
    if (entry.path().extension() == ".mkv") videos.push_back(entry.path());
  ASSERT_EQ(videos.size(), 1u);
  EXPECT_EQ(videos[0].filename().string().rfind("rover-cam0-", 0), 0u) << videos[0];
  fs::remove_all(folder);
}

TEST(WircRecorder, RejectsABadConfigFileNamingTheProblem) {
  auto config =
      fs::temp_directory_path() / ("wirc-recorder-bad-" + std::to_string(getpid()) + ".ini");
  std::ofstream(config) << "[device rover]\nport=99999\n";
  RecorderProcess recorder(0, {"--config", config.string(), "--out", "/tmp"});
  EXPECT_EQ(recorder.wait(), 2);
  EXPECT_NE(recorder.log().find("port"), std::string::npos) << recorder.log();
  fs::remove(config);
}

// A device that never comes is waited for; a --duration that ends with
// nothing recorded is a failure, said as such: whatever earlier runs left
// in the folder (with a service's folder of recordings it exited 0 and
// said nothing, a stranger's trial).
TEST(WircRecorder, ADurationWithoutTheDeviceRecordsNothingAndExitsOne) {
  auto device = startSequenceDevice();
  uint16_t port = device->port();
  RecorderProcess earlier(port, {"--duration", "1"});
  ASSERT_EQ(earlier.wait(), 0) << earlier.log();
  device.reset();
  RecorderProcess recorder(port, {"--duration", "2", "--out", earlier.out().string()});
  EXPECT_EQ(recorder.wait(), 1);
  EXPECT_NE(recorder.statusLines().find("waiting for device"), std::string::npos);
  EXPECT_NE(recorder.log().find("nothing was recorded"), std::string::npos) << recorder.log();
}

}  // namespace
