// How many CIF/15 fps streams one recorder process records, and its CPU and
// memory per stream, beside the stock alternative receiving the same frames.
//   wircam: N × wirc-sim --frames DIR  →  one wirc-recorder with N --device
//   (again with --telemetry-track off: the telemetry in the sidecar only;
//   and with --record-queue 0 too: no queue before the file)
//   stock:  N × multifilesrc ! rtpjpegpay ! udpsink  →  one gst-launch with
//           N × (udpsrc ! rtpjpegdepay ! matroskamux ! filesink)
// Senders are separate processes; the receiving process's CPU (user + system)
// and peak memory come from wait4(), its CPU over its whole life; its CPU
// while recording (from a quarter of the run to the senders' end, out of
// /proc, so without starting and stopping) is shown beside it, and so is
// its private memory halfway through (RssAnon: the peak also counts the
// shared libraries' code, once per process however many streams). Frames are
// counted in the files. The senders stop first and the receiver 1 s later,
// so "lost" counts the frames sent that did not reach a file, not those
// sent while the receiver was told to stop.
// Each recorder run also says when all its cameras were live (its log's
// "NAME: live" lines) and how long it took to stop after SIGINT.
// Usage: bench_recorder_streams [--together] [SECONDS] [N...]   (default 10 s; 1 2 4 8)
//   --together: each recorder run at the same time as a stock run, on the
//   same processors, rather than one after the other (after a 5 s round
//   of both, unmeasured).
#include <gst/gst.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <regex>
#include <set>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "child_process.h"
#include "common/open_file_limit.h"
#include "synthetic_jpeg.h"

namespace {

namespace fs = std::filesystem;

using wircam::bench::spawn;
using wircam::bench::stopGroups;
using wircam::bench::Usage;
using wircam::bench::waitForUsage;

int framesIn(const fs::path& file) {
  std::string description =
      "filesrc location=\"" + file.string() + "\" ! matroskademux ! fakesink name=sink";
  GstElement* pipeline = gst_parse_launch(description.c_str(), nullptr);
  GstElement* sink = gst_bin_get_by_name(GST_BIN(pipeline), "sink");
  int count = 0;  // not static: with --together two runs count at once
  g_object_set(sink, "signal-handoffs", TRUE, nullptr);
  g_signal_connect(sink, "handoff",
                   G_CALLBACK(+[](GstElement*, GstBuffer*, GstPad*, gpointer counter) {
                     ++*static_cast<int*>(counter);
                   }),
                   &count);
  gst_element_set_state(pipeline, GST_STATE_PLAYING);
  GstBus* bus = gst_element_get_bus(pipeline);
  if (GstMessage* m = gst_bus_timed_pop_filtered(
          bus, 30 * GST_SECOND, static_cast<GstMessageType>(GST_MESSAGE_EOS | GST_MESSAGE_ERROR)))
    gst_message_unref(m);
  gst_object_unref(bus);
  gst_element_set_state(pipeline, GST_STATE_NULL);
  gst_object_unref(sink);
  gst_object_unref(pipeline);
  return count;
}

int framesInFolder(const fs::path& folder) {
  int total = 0;
  for (const auto& entry : fs::directory_iterator(folder))
    if (entry.path().extension() == ".mkv") total += framesIn(entry.path());
  return total;
}

using Clock = std::chrono::steady_clock;
// What the receiver gets to take in the last frames after the senders stop.
// (On saturated processors a receiver reads up to 0.7 s behind: with
// 0.3 s, what still waited in its sockets counted as lost.)
constexpr auto kDrain = std::chrono::milliseconds(1000);

double secondsSince(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

// Threads of a process and all its descendants, counted halfway through
// its run.
int threadsOf(pid_t root) {
  std::map<pid_t, pid_t> parents;
  for (const auto& entry : fs::directory_iterator("/proc")) {
    pid_t pid = std::atoi(entry.path().filename().c_str());
    if (pid <= 0) continue;
    std::ifstream stat(entry.path() / "stat");
    std::string line;
    std::getline(stat, line);
    auto close = line.rfind(')');
    if (close == std::string::npos) continue;
    std::istringstream rest(line.substr(close + 2));
    std::string state;
    pid_t parent = 0;
    rest >> state >> parent;
    parents[pid] = parent;
  }
  int count = 0;
  for (const auto& [pid, parent] : parents) {
    pid_t p = pid;
    while (p > 1 && p != root) p = parents.count(p) ? parents[p] : 0;
    if (p != root) continue;
    std::error_code error;
    for (auto it = fs::directory_iterator("/proc/" + std::to_string(pid) + "/task", error);
         !error && it != fs::directory_iterator(); ++it)
      ++count;
  }
  return count;
}

// A process's private memory now (RssAnon: its heap, stacks and other
// anonymous pages), in KB: what each stream adds, without the shared
// libraries' code that the peak (VmHWM) also counts once.
long privateKbOf(pid_t pid) {
  std::ifstream status("/proc/" + std::to_string(pid) + "/status");
  for (std::string line; std::getline(status, line);)
    if (line.starts_with("RssAnon:")) return std::atol(line.c_str() + 8);
  return 0;
}

// A process's CPU (user + system) so far, in seconds.
double cpuSecondsOf(pid_t pid) {
  std::ifstream stat("/proc/" + std::to_string(pid) + "/stat");
  std::string line;
  std::getline(stat, line);
  auto close = line.rfind(')');
  if (close == std::string::npos) return 0;
  std::istringstream rest(line.substr(close + 2));
  std::string field;
  for (int i = 3; i < 14; ++i) rest >> field;  // state … cmajflt
  long user = 0, system = 0;
  rest >> user >> system;
  return static_cast<double>(user + system) / static_cast<double>(sysconf(_SC_CLK_TCK));
}

// The CPU a process spends over a stretch of its run.
class CpuWindow {
 public:
  explicit CpuWindow(pid_t pid) : pid_(pid), cpu_(cpuSecondsOf(pid)), start_(Clock::now()) {}
  // Percent of one core, per stream.
  double end(int streams) const {
    double wall = std::chrono::duration<double>(Clock::now() - start_).count();
    return 100 * (cpuSecondsOf(pid_) - cpu_) / wall / streams;
  }

 private:
  pid_t pid_;
  double cpu_;
  Clock::time_point start_;
};

// "frames sent        N" from a wirc-sim summary.
int framesSent(const fs::path& summary) {
  std::ifstream in(summary);
  std::string line;
  while (std::getline(in, line))
    if (line.find("frames sent") != std::string::npos)
      return std::atoi(line.substr(line.find("sent") + 4).c_str());
  return 0;
}

bool fileSays(const fs::path& file, const std::string& text) {
  std::ifstream in(file);
  for (std::string line; std::getline(in, line);)
    if (line.find(text) != std::string::npos) return true;
  return false;
}

// Cameras the recorder's log has said went live ("NAME: live").
int camerasLive(const fs::path& log) {
  std::ifstream in(log);
  std::set<std::string> live;
  for (std::string line; std::getline(in, line);)
    if (line.ends_with(": live")) live.insert(line.substr(0, line.size() - 6));
  return static_cast<int>(live.size());
}

// One receiver's run: frames sent and recorded, its resources.
struct Run {
  int sent = 0, recorded = 0, threads = 0;
  long privateKb = 0;  // halfway through, as the threads
  Usage usage;
  double seconds = 0;
  double recordingCpu = 0;  // % per stream while recording
  double liveSeconds = -1;  // from its start until every camera said "live" (wirc-recorder)
  double stopSeconds = 0;   // from SIGINT until it exited
  std::string row(int streams) const {
    char text[200];
    int length = std::snprintf(
        text, sizeof text, "lost %4d of %5d, %5.3f / %5.3f %%, %5.2f MB (%5.2f private), %4d thr",
        sent - recorded, sent, 100 * usage.cpuSeconds / seconds / streams, recordingCpu,
        usage.maxRssKb / 1024.0 / streams, privateKb / 1024.0 / streams, threads);
    if (liveSeconds >= 0)
      std::snprintf(text + length, sizeof text - static_cast<size_t>(length),
                    ", live %5.2f s, stop %5.2f s", liveSeconds, stopSeconds);
    else if (stopSeconds > 0)
      std::snprintf(text + length, sizeof text - static_cast<size_t>(length),
                    ", not all live, stop %5.2f s", stopSeconds);
    // Killed after a minute of not stopping: its files may be unfinished.
    return text + std::string(usage.exitCode == 128 + SIGKILL ? " (did not stop: killed)" : "");
  }
};

// N × wirc-sim --frames → one wirc-recorder (with `extra` options).
Run recordWithWircam(const fs::path& work, const fs::path& frames, const fs::path& bin,
                     int basePort, int n, double seconds, const std::string& extra) {
  fs::remove_all(work / "rec");
  // Each configuration's logs apart, kept with WIRCAM_BENCH_KEEP=1.
  fs::path logs = work / ("logs" + std::regex_replace(extra, std::regex("[ -]+"), "-"));
  fs::remove_all(logs);
  fs::create_directories(logs);
  auto simLog = [&](int i) { return logs / ("sim" + std::to_string(i) + ".txt"); };
  std::vector<pid_t> sims;
  std::string devices;
  for (int i = 0; i < n; ++i) {
    int port = basePort + 2 * i;
    sims.push_back(spawn((bin / "wirc-sim").string() + " --port " + std::to_string(port) +
                             " --frames " + frames.string(),
                         simLog(i).string()));
    devices += " --device 127.0.0.1:" + std::to_string(port);
  }
  // "live" is timed from the recorder's start: every device listens first.
  auto listening = Clock::now() + std::chrono::seconds(20);
  for (int i = 0; i < n && Clock::now() < listening;)
    if (fileSays(simLog(i), "listening on"))
      ++i;
    else
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
  Run run;
  auto start = Clock::now();
  fs::path log = logs / "recorder.log";
  pid_t recorder = spawn((bin / "wirc-recorder").string() + devices + " --out " +
                             (work / "rec").string() + " --segment 600" + extra,
                         log.string(), "&1");
  // Waits a quarter of the run, watching for the moment all cameras are live.
  auto quarter = [&] {
    auto until = Clock::now() + std::chrono::duration<double>(seconds / 4);
    while (Clock::now() < until) {
      if (run.liveSeconds < 0 && camerasLive(log) >= n) run.liveSeconds = secondsSince(start);
      std::this_thread::sleep_for(std::chrono::milliseconds(50));
    }
  };
  quarter();
  CpuWindow recording(recorder);
  quarter();
  run.threads = threadsOf(recorder);
  run.privateKb = privateKbOf(recorder);
  quarter();
  quarter();
  run.recordingCpu = recording.end(n);
  stopGroups(sims, SIGINT);
  std::this_thread::sleep_for(kDrain);
  kill(recorder, SIGINT);
  auto stopping = Clock::now();
  run.usage = waitForUsage(recorder);
  run.stopSeconds = secondsSince(stopping);
  run.seconds = secondsSince(start);
  for (int i = 0; i < n; ++i) run.sent += framesSent(simLog(i));
  run.recorded = framesInFolder(work / "rec");
  return run;
}

// N × (multifilesrc ! rtpjpegpay ! udpsink) → one gst-launch of
// N × (udpsrc ! rtpjpegdepay ! matroskamux ! filesink).
Run recordWithStock(const fs::path& work, const fs::path& frames, int basePort, int n,
                    double seconds) {
  fs::remove_all(work / "rtp");
  fs::create_directories(work / "rtp");
  std::string receivers;
  for (int i = 0; i < n; ++i) {
    int port = basePort + 2 * i + 1;
    receivers += " udpsrc port=" + std::to_string(port) +
                 " buffer-size=8388608 "
                 "caps=application/x-rtp,media=video,clock-rate=90000,encoding-name=JPEG,payload=26"
                 " ! rtpjpegdepay ! matroskamux ! filesink location=" +
                 (work / "rtp" / (std::to_string(i) + ".mkv")).string();
  }
  Run run;
  auto start = Clock::now();
  fs::path log = work / "receiver.log";
  // Line-buffered: its "New clock" is in the file when it is said.
  pid_t receiver = spawn("stdbuf -oL gst-launch-1.0 -e" + receivers, log.string());
  // The senders start once every receiver is playing ("New clock"): a
  // packet sent to a port not yet open would count as lost.
  auto playing = Clock::now() + std::chrono::seconds(20);
  while (!fileSays(log, "New clock") && Clock::now() < playing)
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  int framesEach = static_cast<int>(seconds * 15);
  std::vector<pid_t> senders;
  for (int i = 0; i < n; ++i)
    senders.push_back(
        spawn("gst-launch-1.0 multifilesrc location=" + (frames / "%05d.jpg").string() +
              " loop=true num-buffers=" + std::to_string(framesEach) +
              " caps=image/jpeg,width=352,height=288,framerate=15/1 ! identity sleep-time=66666"
              " ! rtpjpegpay ! udpsink host=127.0.0.1 port=" +
              std::to_string(basePort + 2 * i + 1)));
  std::this_thread::sleep_for(std::chrono::duration<double>(seconds / 4));
  CpuWindow recording(receiver);
  std::this_thread::sleep_for(std::chrono::duration<double>(seconds / 4));
  run.threads = threadsOf(receiver);
  run.privateKb = privateKbOf(receiver);
  for (pid_t s : senders) waitpid(s, nullptr, 0);
  run.recordingCpu = recording.end(n);
  std::this_thread::sleep_for(kDrain);
  kill(receiver, SIGINT);
  run.usage = waitForUsage(receiver);
  run.seconds = secondsSince(start);
  run.sent = framesEach * n;
  run.recorded = framesInFolder(work / "rtp");
  return run;
}

// A recorder run over the stock one: CPU while recording, a stream's and a
// frame recorded's (on saturated processors stock records fewer of the
// frames sent, and spends less on those it loses), and peak memory.
std::string ratios(const Run& recorder, const Run& stock) {
  auto perFrame = [](const Run& run) {
    return run.recorded > 0 ? run.recordingCpu / run.recorded : 0.0;
  };
  char text[160];
  std::snprintf(
      text, sizeof text, "wirc-recorder ÷ stock: CPU %.2f× (a frame recorded: %.2f×), memory %.2f×",
      stock.recordingCpu > 0 ? recorder.recordingCpu / stock.recordingCpu : 0.0,
      perFrame(stock) > 0 ? perFrame(recorder) / perFrame(stock) : 0.0,
      stock.usage.maxRssKb > 0 ? static_cast<double>(recorder.usage.maxRssKb) / stock.usage.maxRssKb
                               : 0.0);
  return text;
}

// The recorder's three configurations, each beside stock: one after the
// other, or (together) each at the same time as a stock run of its own, so
// that both see the same load.
void compare(const fs::path& work, const fs::path& bin, int basePort, int n, double seconds,
             bool together) {
  const std::vector<std::string> configurations = {
      "", " --telemetry-track off",
      // One thread a camera, as a stock pipeline: the source's.
      " --telemetry-track off --record-queue 0"};
  std::vector<Run> runs;
  Run stock;
  if (together) {
    // Whatever ran first on this machine, of any configuration, had its
    // simulators starved (they sent 57-64 % of their frames, against 95-99 %
    // for the runs after it, in either order): a round unmeasured first.
    std::thread beside([&] { recordWithStock(work / "stock", work / "frames", basePort, n, 5); });
    recordWithWircam(work / "wircam", work / "frames", bin, basePort, n, 5, configurations[0]);
    beside.join();
  }
  for (const auto& extra : configurations) {
    if (!together) {
      runs.push_back(
          recordWithWircam(work / "wircam", work / "frames", bin, basePort, n, seconds, extra));
      continue;
    }
    std::thread beside(
        [&] { stock = recordWithStock(work / "stock", work / "frames", basePort, n, seconds); });
    runs.push_back(
        recordWithWircam(work / "wircam", work / "frames", bin, basePort, n, seconds, extra));
    beside.join();
    std::printf("%-8d | %s | %s\n", n, runs.back().row(n).c_str(), stock.row(n).c_str());
    std::printf("%-8s   %s\n", "", ratios(runs.back(), stock).c_str());
    std::fflush(stdout);
  }
  if (together) return;
  stock = recordWithStock(work / "stock", work / "frames", basePort, n, seconds);
  std::printf("%-8d | %s | %s | %s | %s\n", n, runs[0].row(n).c_str(), runs[1].row(n).c_str(),
              runs[2].row(n).c_str(), stock.row(n).c_str());
  for (size_t i = 0; i < runs.size(); ++i)
    std::printf("%-8s   %s%s\n", "", ratios(runs[i], stock).c_str(),
                configurations[i].empty() ? " (default)" : configurations[i].c_str());
  std::fflush(stdout);
}

}  // namespace

int main(int argc, char** argv) {
  g_setenv("GST_PLUGIN_PATH", WIRCAM_PLUGIN_DIR, FALSE);
  // Both sides' receivers inherit it: 256 stock pipelines need more than
  // Debian's soft limit of 1024 open files too.
  wircam::raiseOpenFileLimit();
  gst_init(&argc, &argv);
  bool together = argc > 1 && std::string(argv[1]) == "--together";
  if (together) --argc, ++argv;
  double seconds = argc > 1 ? std::atof(argv[1]) : 10;
  std::vector<int> counts;
  for (int i = 2; i < argc; ++i) counts.push_back(std::atoi(argv[i]));
  if (seconds <= 0 || std::any_of(counts.begin(), counts.end(), [](int n) { return n <= 0; })) {
    std::fprintf(stderr,
                 "usage: bench_recorder_streams [--together] [SECONDS [N...]]   (SECONDS per "
                 "run, default 10; N streams, default 1 2 4 8)\n");
    return 2;
  }
  if (counts.empty()) counts = {1, 2, 4, 8};
  fs::path bin = fs::canonical("/proc/self/exe").parent_path();
  fs::path work = fs::temp_directory_path() / ("wircam-bench-rec-" + std::to_string(getpid()));
  fs::create_directories(work / "frames");
  fs::create_directories(work / "wircam");
  fs::create_directories(work / "stock");
  for (int i = 0; i < 30; ++i) {
    auto jpeg = wircam::bench::syntheticJpeg(352, 288, i);
    char name[16];
    std::snprintf(name, sizeof name, "%05d.jpg", i);
    std::ofstream(work / "frames" / name, std::ios::binary)
        .write(reinterpret_cast<const char*>(jpeg.data()),
               static_cast<std::streamsize>(jpeg.size()));
  }
  // Fixed ports below the kernel's ephemeral range (32768 and up), where
  // the sockets bound to port 0 by hundreds of pipelines would take them.
  int basePort = 10000 + getpid() % 10000;

  const char* row = "lost, CPU life / recording, memory (private), threads";
  if (together)
    std::printf(
        "%-8s | wirc-recorder (default; --telemetry-track off; ... --record-queue 0): %s "
        "| at the same time, udpsrc ! rtpjpegdepay ! matroskamux: same\n",
        "streams", row);
  else
    std::printf(
        "%-8s | wirc-recorder: %s | --telemetry-track off: same | ... and "
        "--record-queue 0: same | udpsrc ! rtpjpegdepay ! matroskamux: same\n",
        "streams", row);
  for (int n : counts) compare(work, bin, basePort, n, seconds, together);
  if (g_getenv("WIRCAM_BENCH_KEEP"))
    std::printf("recordings and logs kept in %s\n", work.c_str());
  else
    fs::remove_all(work);
  return 0;
}
