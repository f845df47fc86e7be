// wirc-recorder as users run it (a separate process), against the simulated
// device: segments that play, telemetry beside them, clean finish on SIGINT.
#include <gst/gst.h>
#include <gst/pbutils/pbutils.h>
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <thread>

#include "jpeg_sequence_scene.h"
#include "scene_frames.h"
#include "wirc/device.h"

namespace {

namespace fs = std::filesystem;
using namespace wircam;
using std::chrono::milliseconds;

struct Recorder {
  fs::path out;
  pid_t pid = -1;

  // Records from 127.0.0.1:port into a fresh folder; with port 0 the
  // device and the folder come from `extra` alone.
  Recorder(uint16_t port, std::vector<std::string> extra) {
    out = fs::temp_directory_path() /
          ("wirc-recorder-test-" + std::to_string(getpid()) + "-" + std::to_string(port));
    fs::remove_all(out);
    std::vector<std::string> args = {WIRC_RECORDER, "--status", "0.5"};
    if (port != 0) {
      args.insert(args.end(),
                  {"--device", "127.0.0.1:" + std::to_string(port), "--out", out.string()});
    }
    args.insert(args.end(), extra.begin(), extra.end());
    pid = fork();
    if (pid == 0) {
      std::vector<char*> argv;
      for (auto& a : args) argv.push_back(a.data());
      argv.push_back(nullptr);
      if (!freopen("/dev/null", "w", stdout)) _exit(126);
      execv(argv[0], argv.data());
      _exit(127);
    }
  }
  ~Recorder() { fs::remove_all(out); }

  int wait() {
    int status = 0;
    waitpid(pid, &status, 0);
    return WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
  }

  std::vector<fs::path> files(const std::string& extension) const {
    std::vector<fs::path> found;
    for (const auto& entry : fs::directory_iterator(out))
      if (entry.path().extension() == extension) found.push_back(entry.path());
    std::sort(found.begin(), found.end());
    return found;
  }
};

GstClockTime durationOf(const fs::path& file) {
  GstDiscoverer* discoverer = gst_discoverer_new(10 * GST_SECOND, nullptr);
  std::string uri = "file://" + fs::absolute(file).string();
  GstDiscovererInfo* info = gst_discoverer_discover_uri(discoverer, uri.c_str(), nullptr);
  GstClockTime duration = info ? gst_discoverer_info_get_duration(info) : GST_CLOCK_TIME_NONE;
  if (info) gst_discoverer_info_unref(info);
  g_object_unref(discoverer);
  return duration;
}

// Frames in a recorded file, checking on the way that their timestamps rise.
struct Contents {
  int frames = 0;
  bool monotonic = true;
};

Contents contentsOf(const fs::path& file) {
  std::string description =
      "filesrc location=\"" + file.string() + "\" ! matroskademux ! fakesink name=sink";
  GstElement* pipeline = gst_parse_launch(description.c_str(), nullptr);
  GstElement* sink = gst_bin_get_by_name(GST_BIN(pipeline), "sink");
  struct Count {
    Contents contents;
    GstClockTime last = GST_CLOCK_TIME_NONE;
  } count;
  g_object_set(sink, "signal-handoffs", TRUE, nullptr);
  g_signal_connect(sink, "handoff",
                   G_CALLBACK(+[](GstElement*, GstBuffer* buffer, GstPad*, gpointer data) {
                     auto* c = static_cast<Count*>(data);
                     GstClockTime pts = GST_BUFFER_PTS(buffer);
                     if (GST_CLOCK_TIME_IS_VALID(c->last) && pts <= c->last)
                       c->contents.monotonic = false;
                     c->last = pts;
                     ++c->contents.frames;
                   }),
                   &count);
  gst_element_set_state(pipeline, GST_STATE_PLAYING);
  GstBus* bus = gst_element_get_bus(pipeline);
  gst_message_unref(gst_bus_timed_pop_filtered(
      bus, 10 * GST_SECOND, static_cast<GstMessageType>(GST_MESSAGE_EOS | GST_MESSAGE_ERROR)));
  gst_object_unref(bus);
  gst_element_set_state(pipeline, GST_STATE_NULL);
  gst_object_unref(sink);
  gst_object_unref(pipeline);
  return count.contents;
}

std::unique_ptr<wirc::Device> startDevice() {
  auto device =
      wirc::Device::start({.port = 0, .fragmentSize = 8000},
                          std::make_shared<sim::JpegSequenceScene>(wircam::testing::sceneFrames()));
  EXPECT_TRUE(device.has_value());
  return std::move(*device);
}

TEST(WircRecorder, RecordsPlayableSegmentsWithTelemetry) {
  auto device = startDevice();
  Recorder recorder(device->port(), {"--segment", "2", "--duration", "5"});
  ASSERT_EQ(recorder.wait(), 0);
  auto videos = recorder.files(".mkv");
  ASSERT_GE(videos.size(), 2u);
  GstClockTime total = 0;
  for (const auto& video : videos) {
    GstClockTime duration = durationOf(video);
    ASSERT_TRUE(GST_CLOCK_TIME_IS_VALID(duration)) << video;
    total += duration;
    auto telemetry = video;
    telemetry.replace_extension(".jsonl");
    ASSERT_TRUE(fs::exists(telemetry)) << telemetry;
  }
  // About the 5 s asked for, less the start-up before the first frame.
  EXPECT_GT(total, 3 * GST_SECOND);
  EXPECT_LT(total, 6 * GST_SECOND);
  std::ifstream first(recorder.files(".jsonl")[0]);
  std::string line;
  bool stats = false;
  while (std::getline(first, line))
    stats = stats || line.find("\"type\":\"stats\"") != std::string::npos;
  EXPECT_TRUE(stats);
}

TEST(WircRecorder, RecordsEveryFrameDeliveredInOrder) {
  auto device = startDevice();
  Recorder recorder(device->port(), {"--segment", "2", "--duration", "5"});
  ASSERT_EQ(recorder.wait(), 0);
  std::this_thread::sleep_for(milliseconds(100));
  uint64_t sent = device->stats().framesSent;  // to this receiver, none lost on loopback
  int recorded = 0;
  for (const auto& video : recorder.files(".mkv")) {
    auto contents = contentsOf(video);
    EXPECT_TRUE(contents.monotonic) << video;
    recorded += contents.frames;
  }
  ASSERT_GT(sent, 40u);
  // The frame in flight when the stream stopped may be missing.
  EXPECT_LE(static_cast<uint64_t>(recorded), sent);
  EXPECT_GE(static_cast<uint64_t>(recorded) + 2, sent);
}

TEST(WircRecorder, SigintFinishesEveryFileAndExitsZero) {
  auto device = startDevice();
  Recorder recorder(device->port(), {"--segment", "60"});
  std::this_thread::sleep_for(milliseconds(3000));
  kill(recorder.pid, SIGINT);
  ASSERT_EQ(recorder.wait(), 0);
  auto videos = recorder.files(".mkv");
  ASSERT_EQ(videos.size(), 1u);
  GstClockTime duration = durationOf(videos[0]);
  ASSERT_TRUE(GST_CLOCK_TIME_IS_VALID(duration));
  EXPECT_GT(duration, GST_SECOND);
}

TEST(WircRecorder, AfterKill9TheOpenSegmentPlaysUpToItsLastSecond) {
  auto device = startDevice();
  Recorder recorder(device->port(), {"--segment", "60"});
  std::this_thread::sleep_for(milliseconds(4000));
  kill(recorder.pid, SIGKILL);
  recorder.wait();
  auto videos = recorder.files(".mkv");
  ASSERT_EQ(videos.size(), 1u);
  GstClockTime duration = durationOf(videos[0]);
  ASSERT_TRUE(GST_CLOCK_TIME_IS_VALID(duration));
  // About 3.5 s were streamed; clusters of 1 s lose at most the last one.
  EXPECT_GT(duration, 2 * GST_SECOND);
}

TEST(WircRecorder, StartsANewSegmentWhenTheDeviceComesBack) {
  auto device = startDevice();
  uint16_t port = device->port();
  Recorder recorder(port, {"--segment", "60"});
  std::this_thread::sleep_for(milliseconds(2500));
  device.reset();  // the vehicle goes away...
  std::this_thread::sleep_for(milliseconds(1000));
  device =
      wirc::Device::start({.port = port, .fragmentSize = 8000},
                          std::make_shared<sim::JpegSequenceScene>(wircam::testing::sceneFrames()))
          .value();  // ...and comes back
  std::this_thread::sleep_for(milliseconds(4000));
  kill(recorder.pid, SIGINT);
  ASSERT_EQ(recorder.wait(), 0);
  auto videos = recorder.files(".mkv");
  ASSERT_EQ(videos.size(), 2u);
  for (const auto& video : videos) EXPECT_TRUE(GST_CLOCK_TIME_IS_VALID(durationOf(video))) << video;
  std::ifstream first(recorder.files(".jsonl")[0]);
  std::string text((std::istreambuf_iterator<char>(first)), {});
  EXPECT_NE(text.find("connection to the device lost"), std::string::npos);
}

TEST(WircRecorder, DeletesTheOldestSegmentsToStayUnderMaxBytes) {
  auto device = startDevice();
  Recorder recorder(device->port(), {"--segment", "1", "--duration", "6", "--max-bytes", "400K"});
  ASSERT_EQ(recorder.wait(), 0);
  uint64_t total = 0, largest = 0;
  for (const auto& entry : fs::directory_iterator(recorder.out)) {
    total += entry.file_size();
    largest = std::max<uint64_t>(largest, entry.file_size());
  }
  auto videos = recorder.files(".mkv");
  ASSERT_FALSE(videos.empty());
  EXPECT_LT(videos.size(), 5u);  // about 6 one-second segments were made
  // Checked when a segment closes: at most the newest one beyond the cap.
  EXPECT_LE(total, 400000 + 2 * largest);
  // The oldest went first: segment 000 is gone.
  EXPECT_EQ(videos.front().string().find("-000.mkv"), std::string::npos) << videos.front();
  for (const auto& video : videos)
    EXPECT_TRUE(fs::exists(fs::path(video).replace_extension(".jsonl")));
}

TEST(WircRecorder, TakesItsDevicesFromAConfigFile) {
  auto device = startDevice();
  auto folder = fs::temp_directory_path() / ("wirc-recorder-config-" + std::to_string(getpid()));
  fs::remove_all(folder);
  fs::create_directories(folder);
  auto config = folder / "recorder.ini";
  std::ofstream(config) << "[recorder]\nout=" << (folder / "out").string()
                        << "\nsegment=60\n\n[device rover]\nhost=127.0.0.1\nport=" << device->port()
                        << "\ncameras=0\n";
  Recorder recorder(0, {"--config", config.string(), "--duration", "3"});
  ASSERT_EQ(recorder.wait(), 0);
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
  Recorder recorder(0, {"--config", config.string(), "--out", "/tmp"});
  EXPECT_EQ(recorder.wait(), 2);
  fs::remove(config);
}

TEST(WircRecorder, ReportsAnUnreachableDevice) {
  auto device = startDevice();
  uint16_t port = device->port();
  device.reset();
  Recorder recorder(port, {"--duration", "3"});
  EXPECT_EQ(recorder.wait(), 1);
}

}  // namespace
