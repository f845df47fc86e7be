// End to end over loopback: CPU the receiving process spends per frame.
//   wircam:  wirc-sim --frames DIR  →  wircsrc ! fakesink
//   stock:   multifilesrc DIR ! rtpjpegpay ! udpsink  →  udpsrc ! rtpjpegdepay ! fakesink
// Both senders run as separate processes and send the same JPEG files at the
// same rate; only the receiver's CPU (user + system, all its threads) counts.
// Usage: bench_end_to_end [SECONDS [ROUNDS]]   (default 5 per receiver and round, 3 rounds)
#include <gst/gst.h>
#include <signal.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>
#include <thread>
#include <vector>

#include "bench_arguments.h"
#include "child_process.h"
#include "synthetic_jpeg.h"
#include "thread_times.h"

namespace {

namespace fs = std::filesystem;

struct Case {
  int width;
  int height;
  int fps;
};

double cpuSeconds() {
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  return usage.ru_utime.tv_sec + usage.ru_stime.tv_sec +
         (usage.ru_utime.tv_usec + usage.ru_stime.tv_usec) / 1e6;
}

using wircam::bench::spawn;

void stop(pid_t pid) { wircam::bench::stopGroup(pid, SIGTERM); }

// One receiver's CPU per frame: the whole process, and its source's
// streaming thread (named "NAME:src") apart from the rest (for wircsrc the
// vehicle link's event loop: keepalives and status reports).
struct Result {
  double cpuPerFrameUs = 0;
  double streamingUsPerFrame = 0;
  double streamingWakeUpsPerFrame = 0;
  double otherWakeUpsPerFrame = 0;
  uint64_t frames = 0;

  double otherUsPerFrame() const { return cpuPerFrameUs - streamingUsPerFrame; }
};

// Runs the receiver pipeline for `seconds` and counts frames at its sink.
Result receive(const std::string& description, double seconds) {
  GstElement* pipeline = gst_parse_launch(description.c_str(), nullptr);
  GstElement* sink = gst_bin_get_by_name(GST_BIN(pipeline), "sink");
  static uint64_t frames;
  frames = 0;
  g_object_set(sink, "signal-handoffs", TRUE, nullptr);
  g_signal_connect(sink, "handoff",
                   G_CALLBACK(+[](GstElement*, GstBuffer*, GstPad*, gpointer) { ++frames; }),
                   nullptr);
  gst_element_set_state(pipeline, GST_STATE_PLAYING);
  std::this_thread::sleep_for(std::chrono::milliseconds(1000));  // warm up, log in
  uint64_t startFrames = frames;
  double startCpu = cpuSeconds();
  auto startThreads = wircam::bench::threadTimes();
  std::this_thread::sleep_for(std::chrono::duration<double>(seconds));
  double cpu = cpuSeconds() - startCpu;
  auto threads = wircam::bench::threadTimes() - startThreads;
  uint64_t counted = frames - startFrames;
  gst_element_set_state(pipeline, GST_STATE_NULL);
  gst_object_unref(sink);
  gst_object_unref(pipeline);
  if (!counted) return {};
  double perFrame = 1.0 / static_cast<double>(counted);
  Result result{.cpuPerFrameUs = cpu * perFrame * 1e6, .frames = counted};
  for (const auto& [name, time] : threads) {
    bool streaming = name.size() > 4 && name.compare(name.size() - 4, 4, ":src") == 0;
    if (streaming) {
      result.streamingUsPerFrame += static_cast<double>(time.cpuNs) / 1e3 * perFrame;
      result.streamingWakeUpsPerFrame += static_cast<double>(time.wakeUps) * perFrame;
    } else {
      result.otherWakeUpsPerFrame += static_cast<double>(time.wakeUps) * perFrame;
    }
  }
  return result;
}

void printRow(const char* label, const char* receiver, const Result& r) {
  std::printf("%-12s %-22s %7.1f %10.1f (%4.2f) %10.1f (%4.2f) %7llu\n", label, receiver,
              r.cpuPerFrameUs, r.streamingUsPerFrame, r.streamingWakeUpsPerFrame,
              r.otherUsPerFrame(), r.otherWakeUpsPerFrame,
              static_cast<unsigned long long>(r.frames));
}

// "max PCD gap        100 ms" in wirc-sim's summary → "100 ms".
std::string longestPcdGapIn(const fs::path& summary) {
  std::ifstream in(summary);
  for (std::string line; std::getline(in, line);)
    if (auto at = line.find("max PCD gap"); at != std::string::npos)
      return line.substr(line.find_first_not_of(' ', at + 11));
  return "unknown";
}

double ratio(double ours, double stock) { return stock > 0 ? ours / stock : 0; }

// The median of a few values (the rounds' ratios).
double median(std::vector<double> values) {
  std::sort(values.begin(), values.end());
  size_t n = values.size();
  return n == 0 ? 0 : n % 2 ? values[n / 2] : (values[n / 2 - 1] + values[n / 2]) / 2;
}

}  // namespace

int main(int argc, char** argv) {
  g_setenv("GST_PLUGIN_PATH", WIRCAM_PLUGIN_DIR, FALSE);  // the build's wircsrc
  gst_init(&argc, &argv);
  auto arguments = wircam::bench::positiveArguments(
      argc, argv, {5, 3},
      "usage: bench_end_to_end [SECONDS [ROUNDS]]   (SECONDS measured per receiver and round, "
      "default 5; ROUNDS default 3)");
  if (!arguments) return 2;
  double seconds = (*arguments)[0];
  int rounds = static_cast<int>((*arguments)[1]);
  fs::path self = fs::canonical("/proc/self/exe").parent_path();
  std::string sim = (self / "wirc-sim").string();

  std::printf(
      "CPU per frame in µs (wake-ups per frame): the whole receiving process, its\n"
      "streaming thread, and its other threads (wircsrc's: the vehicle link).\n"
      "The receivers take turns, %d rounds: this machine's speed drifts over\n"
      "seconds, and a ratio is taken within a round.\n",
      rounds);
  std::printf("%-12s %-22s %7s %17s %17s %7s\n", "stream", "receiver", "whole", "streaming",
              "other", "frames");
  for (Case c : {Case{352, 288, 15}, Case{1280, 720, 30}}) {
    fs::path dir = fs::temp_directory_path() / ("wircam-e2e-" + std::to_string(c.width));
    fs::create_directories(dir);
    for (int i = 0; i < 30; ++i) {
      auto jpeg = wircam::bench::syntheticJpeg(c.width, c.height, i);
      char name[32];
      std::snprintf(name, sizeof name, "%05d.jpg", i);
      std::ofstream(dir / name, std::ios::binary)
          .write(reinterpret_cast<const char*>(jpeg.data()),
                 static_cast<std::streamsize>(jpeg.size()));
    }
    // Ports from the pid keep parallel runs apart.
    int port = 10000 + getpid() % 20000;  // below the ephemeral ports (32768 and up)
    int rtpPort = port + 1;

    // The simulator's summary at its end says the longest gap between two
    // commands (PCD) it heard: the keepalive's, however they were sent.
    auto receiveFromSimulator = [&](std::string& longestPcdGap) {
      fs::path summary = dir.string() + "-sim.txt";
      pid_t sender = spawn(sim + " --bind 127.0.0.1 --port " + std::to_string(port) + " --fps " +
                               std::to_string(c.fps) + " --frames " + dir.string(),
                           summary.string());
      std::this_thread::sleep_for(std::chrono::milliseconds(500));
      auto result = receive("wircsrc host=127.0.0.1 port=" + std::to_string(port) +
                                " ! fakesink name=sink sync=false",
                            seconds);
      stop(sender);
      longestPcdGap = longestPcdGapIn(summary);
      fs::remove(summary);
      return result;
    };
    // multifilesrc does not timestamp: identity's sleep paces it instead.
    auto receiveRtp = [&] {
      pid_t sender =
          spawn("gst-launch-1.0 multifilesrc location=" + (dir / "%05d.jpg").string() +
                " loop=true caps=image/jpeg,width=" + std::to_string(c.width) +
                ",height=" + std::to_string(c.height) + ",framerate=" + std::to_string(c.fps) +
                "/1 ! identity sleep-time=" + std::to_string(1000000 / c.fps) +
                " ! rtpjpegpay ! udpsink host=127.0.0.1 port=" + std::to_string(rtpPort));
      auto result = receive(
          "udpsrc port=" + std::to_string(rtpPort) +
              " buffer-size=8388608 "
              "caps=application/x-rtp,media=video,clock-rate=90000,encoding-name=JPEG,payload=26 "
              "! rtpjpegdepay ! fakesink name=sink sync=false",
          seconds);
      stop(sender);
      return result;
    };

    char label[32];
    std::snprintf(label, sizeof label, "%dx%d@%d", c.width, c.height, c.fps);
    std::vector<double> whole, streaming;
    std::string longestPcdGap, longestOfAll;
    for (int round = 0; round < rounds; ++round) {
      auto wircam = receiveFromSimulator(longestPcdGap);
      auto rtp = receiveRtp();
      printRow(label, "wircsrc", wircam);
      printRow(label, "udpsrc ! rtpjpegdepay", rtp);
      whole.push_back(ratio(wircam.cpuPerFrameUs, rtp.cpuPerFrameUs));
      streaming.push_back(ratio(wircam.streamingUsPerFrame, rtp.streamingUsPerFrame));
      longestOfAll += (round ? ", " : "") + longestPcdGap;
    }
    fs::remove_all(dir);
    auto [lowest, highest] = std::minmax_element(whole.begin(), whole.end());
    std::printf(
        "%-12s wircsrc ÷ stock, median of %d rounds: whole %.2f× (%.2f–%.2f), streaming thread "
        "%.2f×; keepalive on, longest PCD gaps %s\n",
        label, rounds, median(whole), *lowest, *highest, median(streaming), longestOfAll.c_str());
  }
  return 0;
}
