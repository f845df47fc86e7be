// What --mqtt costs: one wirc-recorder finding tags in N streams, without
// MQTT and then publishing status, detections (every frame with a tag) and
// events to a real mosquitto with a subscriber reading everything.
//   N × wirc-sim --frames DIR (the follow scene's frames, a tag in each)
//   → wirc-recorder --detect tag36h11 [--mqtt mqtt://127.0.0.1:PORT]
// The recorder's CPU (user + system) and peak memory come from wait4();
// the messages are counted at the subscriber.
// Usage: bench_recorder_mqtt [SECONDS] [N]   (default 15 s, 16 streams)
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>
#include <thread>
#include <vector>

#include "bench_arguments.h"
#include "child_process.h"
#include "common/socket.h"
#include "scene_frames.h"

namespace {

namespace fs = std::filesystem;
using wircam::bench::spawn;
using wircam::bench::stopGroup;
using wircam::bench::stopGroups;
using wircam::bench::Usage;
using wircam::bench::waitForUsage;

size_t linesIn(const fs::path& file, const std::string& containing) {
  std::ifstream in(file);
  size_t count = 0;
  for (std::string line; std::getline(in, line);)
    count += line.find(containing) != std::string::npos;
  return count;
}

}  // namespace

int main(int argc, char** argv) {
  auto arguments = wircam::bench::positiveArguments(
      argc, argv, {15, 16},
      "usage: bench_recorder_mqtt [SECONDS [N]]   (default 15 s, 16 streams)");
  if (!arguments) return 2;
  double seconds = (*arguments)[0];
  int streams = static_cast<int>((*arguments)[1]);
  fs::path bin = fs::canonical("/proc/self/exe").parent_path();
  fs::path work = fs::temp_directory_path() / ("wircam-bench-mqtt-" + std::to_string(getpid()));
  fs::create_directories(work / "frames");
  const auto& frames = wircam::testing::sceneFrames();
  for (size_t i = 0; i < frames.size(); ++i) {
    char name[32];
    std::snprintf(name, sizeof name, "%05zu.jpg", i);
    std::ofstream(work / "frames" / name, std::ios::binary)
        .write(reinterpret_cast<const char*>(frames[i].data()),
               static_cast<std::streamsize>(frames[i].size()));
  }
  uint16_t brokerPort = [] {
    auto socket = wircam::listenTcp(wircam::SocketAddress::loopback(0));
    return socket ? wircam::localAddress(socket->get()).port() : uint16_t{0};
  }();
  std::ofstream(work / "mosquitto.conf")
      << "listener " << brokerPort << " 127.0.0.1\nallow_anonymous true\npersistence false\n";
  pid_t broker = spawn("mosquitto -c " + (work / "mosquitto.conf").string());
  std::this_thread::sleep_for(std::chrono::milliseconds(500));

  // Below the kernel's ephemeral range (32768 and up).
  int basePort = 10000 + getpid() % 10000;
  std::vector<pid_t> sims;
  std::string devices;
  for (int i = 0; i < streams; ++i) {
    int port = basePort + i;
    sims.push_back(spawn((bin / "wirc-sim").string() + " --port " + std::to_string(port) +
                         " --frames " + (work / "frames").string()));
    devices += " --device 127.0.0.1:" + std::to_string(port);
  }
  std::this_thread::sleep_for(std::chrono::milliseconds(500));

  std::printf("%d streams, %.0f s each run, tags in every frame\n", streams, seconds);
  std::printf("%-28s | %-14s | %-9s | %s\n", "recorder", "CPU %/stream", "MB", "MQTT messages/s");
  double withoutCpu = 0;
  for (bool mqtt : {false, true}) {
    fs::remove_all(work / "rec");
    pid_t subscriber = 0;
    if (mqtt)
      subscriber = spawn("mosquitto_sub -p " + std::to_string(brokerPort) + " -t 'wircam/#' -v",
                         (work / "messages.txt").string());
    std::string command = (bin / "wirc-recorder").string() + devices + " --out " +
                          (work / "rec").string() + " --detect tag36h11 --segment 600 --duration " +
                          std::to_string(seconds);
    if (mqtt) command += " --mqtt mqtt://127.0.0.1:" + std::to_string(brokerPort);
    Usage usage = waitForUsage(spawn(command));
    double cpuPerStream = 100.0 * usage.cpuSeconds / seconds / streams;
    std::string messages = "-";
    if (mqtt) {
      std::this_thread::sleep_for(std::chrono::milliseconds(300));
      stopGroup(subscriber, SIGTERM);
      size_t detections = linesIn(work / "messages.txt", "/detections ");
      size_t all = linesIn(work / "messages.txt", "wircam/");
      char text[96];
      std::snprintf(text, sizeof text, "%.0f (%.0f detections)", static_cast<double>(all) / seconds,
                    static_cast<double>(detections) / seconds);
      messages = text;
    } else {
      withoutCpu = cpuPerStream;
    }
    std::printf("%-28s | %6.2f         | %5.1f     | %s\n",
                mqtt ? "--detect --mqtt" : "--detect (no MQTT)", cpuPerStream,
                static_cast<double>(usage.maxRssKb) / 1024, messages.c_str());
    if (mqtt)
      std::printf("MQTT adds %.2f %% CPU per stream (%.0f %% more than without)\n",
                  cpuPerStream - withoutCpu, 100.0 * (cpuPerStream - withoutCpu) / withoutCpu);
  }
  stopGroups(sims, SIGINT);
  stopGroup(broker, SIGTERM);
  fs::remove_all(work);
  return 0;
}
