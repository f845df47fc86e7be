// End to end over loopback: CPU the receiving process spends per frame.
//   wircam:  wirc-sim --frames DIR  →  wircsrc ! fakesink
//   stock:   multifilesrc DIR ! rtpjpegpay ! udpsink  →  udpsrc ! rtpjpegdepay ! fakesink
// Both senders run as separate processes and send the same JPEG files at the
// same rate; only the receiver's CPU (user + system, all its threads) counts.
// Usage: bench_end_to_end [SECONDS]   (default 5 per case)
#include <gst/gst.h>
#include <signal.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>
#include <thread>

#include "child_process.h"
#include "synthetic_jpeg.h"

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

struct Result {
  double cpuPerFrameUs = 0;
  uint64_t frames = 0;
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
  std::this_thread::sleep_for(std::chrono::duration<double>(seconds));
  double cpu = cpuSeconds() - startCpu;
  uint64_t counted = frames - startFrames;
  gst_element_set_state(pipeline, GST_STATE_NULL);
  gst_object_unref(sink);
  gst_object_unref(pipeline);
  return {counted ? cpu / static_cast<double>(counted) * 1e6 : 0, counted};
}

}  // namespace

int main(int argc, char** argv) {
  gst_init(&argc, &argv);
  double seconds = argc > 1 ? std::atof(argv[1]) : 5;
  fs::path self = fs::canonical("/proc/self/exe").parent_path();
  std::string sim = (self / "wirc-sim").string();

  std::printf("%-16s %-28s %-28s %s\n", "stream", "wircsim→wircsrc µs CPU/frame",
              "rtpjpegpay→rtpjpegdepay", "ratio");
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
    int port = 20000 + getpid() % 20000;

    pid_t sender = spawn(sim + " --bind 127.0.0.1 --port " + std::to_string(port) + " --fps " +
                         std::to_string(c.fps) + " --frames " + dir.string());
    std::this_thread::sleep_for(std::chrono::milliseconds(500));
    auto wircam = receive(
        "wircsrc host=127.0.0.1 port=" + std::to_string(port) + " ! fakesink name=sink sync=false",
        seconds);
    stop(sender);

    int rtpPort = port + 1;
    // multifilesrc does not timestamp: identity's sleep paces it instead.
    sender = spawn("gst-launch-1.0 multifilesrc location=" + (dir / "%05d.jpg").string() +
                   " loop=true caps=image/jpeg,width=" + std::to_string(c.width) +
                   ",height=" + std::to_string(c.height) + ",framerate=" + std::to_string(c.fps) +
                   "/1 ! identity sleep-time=" + std::to_string(1000000 / c.fps) +
                   " ! rtpjpegpay ! udpsink host=127.0.0.1 port=" + std::to_string(rtpPort));
    auto rtp = receive(
        "udpsrc port=" + std::to_string(rtpPort) +
            " buffer-size=8388608 "
            "caps=application/x-rtp,media=video,clock-rate=90000,encoding-name=JPEG,payload=26 "
            "! rtpjpegdepay ! fakesink name=sink sync=false",
        seconds);
    stop(sender);
    fs::remove_all(dir);

    char label[32];
    std::snprintf(label, sizeof label, "%dx%d@%d", c.width, c.height, c.fps);
    std::printf("%-16s %8.1f (%5llu frames)          %8.1f (%5llu frames)          %.2f×\n", label,
                wircam.cpuPerFrameUs, static_cast<unsigned long long>(wircam.frames),
                rtp.cpuPerFrameUs, static_cast<unsigned long long>(rtp.frames),
                wircam.cpuPerFrameUs > 0 ? rtp.cpuPerFrameUs / wircam.cpuPerFrameUs : 0.0);
  }
  return 0;
}
