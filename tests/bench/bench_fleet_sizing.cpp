// A fleet at the size issue 56 names, 100 recorders of 256 cameras, on one
// real mosquitto: this program plays the recorders (one MQTT client each, as
// each recorder has one), each announcing itself retained with its cameras
// and their vehicles, saying it is online, and publishing every camera's
// retained status once a second (what a recorder does while fps and battery
// move; every 5 s when nothing does). While they publish, side by side:
//   1. the stock reader: mosquitto_sub on the topics a fleet recorder reads;
//   2. wirc-recorder --fleet reading them, and GET /api/fleet asked of it
//      (how long, how big, whether every camera is there and live);
// each reader's and the broker's CPU (from /proc), the messages a second
// and the retained topics.
// Usage: bench_fleet_sizing [RECORDERS] [CAMERAS] [SECONDS]   (default 100 256 15)
#include <signal.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <functional>
#include <memory>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "bench_arguments.h"
#include "child_process.h"
#include "fleet/fleet_announcement.h"
#include "fleet/mqtt_client.h"
#include "free_port.h"

namespace {

namespace fs = std::filesystem;
using namespace wircam::recorder;
using wircam::bench::cpuSecondsOf;
using wircam::bench::spawn;
using wircam::bench::stopGroup;
using Clock = std::chrono::steady_clock;

long residentKbOf(pid_t pid) {
  std::ifstream status("/proc/" + std::to_string(pid) + "/status");
  for (std::string line; std::getline(status, line);)
    if (line.starts_with("VmRSS:")) return std::stol(line.substr(6));
  return 0;
}

struct SimulatedRecorder {
  std::string prefix;
  std::unique_ptr<MqttClient> client;
};

// A recorder's camera status as fleetStatusJson makes it, fps and battery
// moving a little each second.
std::string statusOf(int second, int camera) {
  nlohmann::json status = {
      {"state", "live"},
      {"state_since_utc", "2026-11-28T10:00:00.000Z"},
      {"fps", 14.9 + ((second + camera) % 3) / 10.0},
      {"loss", 0.0},
      {"battery_v", 8.1 - (second % 50) / 1000.0},
      {"has_control", true},
      {"following", false},
      {"target", -1},
      {"position", nullptr},
      {"vehicle",
       {{"name", "car-" + std::to_string(camera)}, {"serial", "S" + std::to_string(camera)}}}};
  return status.dump();
}

std::string announcementOf(int recorder, int cameras, const std::string& prefix) {
  Announcement a;
  a.id = "bench-recorder-" + std::to_string(recorder);
  a.host = "host" + std::to_string(recorder);
  a.version = "0.1.0";
  a.mqttPrefix = prefix;
  a.http = "http://host" + std::to_string(recorder) + ":8080/";
  a.seenUnixMs = 1795532375467;
  for (int c = 0; c < cameras; ++c)
    a.cameras.push_back({"car" + std::to_string(c) + "-cam0",
                         VehicleIdentity{"car-" + std::to_string(c), "S" + std::to_string(c)}, ""});
  return toJson(a).dump();
}

}  // namespace

int main(int argc, char** argv) {
  auto arguments = wircam::bench::positiveArguments(
      argc, argv, {100, 256, 15},
      "usage: bench_fleet_sizing [RECORDERS [CAMERAS [SECONDS]]]   (default 100 256 15)");
  if (!arguments) return 2;
  int recorders = static_cast<int>((*arguments)[0]);
  int cameras = static_cast<int>((*arguments)[1]);
  double seconds = (*arguments)[2];
  fs::path bin = fs::canonical("/proc/self/exe").parent_path();
  fs::path work = fs::temp_directory_path() / ("wircam-bench-fleet-" + std::to_string(getpid()));
  fs::create_directories(work);
  uint16_t brokerPort = wircam::testing::freeLoopbackPort();
  std::ofstream(work / "mosquitto.conf")
      << "listener " << brokerPort << " 127.0.0.1\nallow_anonymous true\npersistence false\n"
      << "max_queued_messages 100000\n";
  pid_t broker = spawn("mosquitto -c " + (work / "mosquitto.conf").string());
  std::this_thread::sleep_for(std::chrono::milliseconds(500));
  auto url = parseMqttUrl("mqtt://127.0.0.1:" + std::to_string(brokerPort));

  // The recorders: announced, online, then their statuses.
  std::vector<SimulatedRecorder> fleet(static_cast<size_t>(recorders));
  for (int r = 0; r < recorders; ++r) {
    auto& member = fleet[static_cast<size_t>(r)];
    member.prefix = "bench/r" + std::to_string(r);
    MqttClient::Handlers handlers;
    std::string prefix = member.prefix, announcement = announcementOf(r, cameras, member.prefix);
    std::string topic = announcementTopic("bench-recorder-" + std::to_string(r));
    handlers.connected = [prefix, announcement, topic](MqttClient& client) {
      client.publish(prefix + "/available", "online", true, 1);
      client.publish(topic, announcement, true, 1);
    };
    auto client = MqttClient::start(*url, "bench-" + std::to_string(r),
                                    {prefix + "/available", "offline"}, std::move(handlers));
    if (!client) {
      std::fprintf(stderr, "bench_fleet_sizing: %s\n", client.error().c_str());
      return 1;
    }
    member.client = std::move(*client);
  }
  std::atomic<bool> publishing{true};
  std::atomic<uint64_t> published{0};
  // A tenth of the statuses every 100 ms: once a second each.
  std::thread publisher([&] {
    auto next = Clock::now();
    for (int tick = 0; publishing; ++tick) {
      int second = tick / 10;
      for (int r = 0; r < recorders; ++r)
        for (int c = tick % 10; c < cameras; c += 10)
          if (fleet[static_cast<size_t>(r)].client->publish(fleet[static_cast<size_t>(r)].prefix +
                                                                "/car" + std::to_string(c) +
                                                                "-cam0/status",
                                                            statusOf(second, c), true))
            ++published;
      next += std::chrono::milliseconds(100);
      std::this_thread::sleep_until(next);
    }
  });
  std::this_thread::sleep_for(std::chrono::seconds(3));  // all retained once

  std::printf(
      "%d recorders x %d cameras: %d retained topics (an announcement, an availability "
      "and %d statuses each)\n",
      recorders, cameras, recorders * (cameras + 2), cameras);
  std::printf("%-36s | %8s | %10s | %9s | %s\n", "reader", "reader CPU %", "broker CPU %",
              "reader MB", "messages/s published");
  auto measure = [&](const char* name, pid_t reader, const std::function<void()>& during) {
    double readerBefore = cpuSecondsOf(reader), brokerBefore = cpuSecondsOf(broker);
    uint64_t before = published;
    auto begun = Clock::now();
    during();
    std::this_thread::sleep_until(begun + std::chrono::duration<double>(seconds));
    double elapsed = std::chrono::duration<double>(Clock::now() - begun).count();
    double readerCpu = 100 * (cpuSecondsOf(reader) - readerBefore) / elapsed;
    double brokerCpu = 100 * (cpuSecondsOf(broker) - brokerBefore) / elapsed;
    std::printf("%-36s | %12.1f | %12.1f | %9.1f | %.0f\n", name, readerCpu, brokerCpu,
                static_cast<double>(residentKbOf(reader)) / 1024,
                static_cast<double>(published - before) / elapsed);
    return readerCpu;
  };

  std::string port = std::to_string(brokerPort);
  pid_t stock = spawn("mosquitto_sub -p " + port +
                      " -t 'wircam-fleet/recorders/+' -t 'bench/+/available' -t "
                      "'bench/+/+/status' -v");
  std::this_thread::sleep_for(std::chrono::seconds(2));  // the retained ones first
  double stockCpu = measure("mosquitto_sub (stock)", stock, [] {});
  stopGroup(stock, SIGTERM);

  uint16_t httpPort = wircam::testing::freeLoopbackPort();
  pid_t recorder = spawn(
      (bin / "wirc-recorder").string() + " --device 127.0.0.1:1 --out " + (work / "rec").string() +
          " --http 127.0.0.1:" + std::to_string(httpPort) + " --mqtt mqtt://127.0.0.1:" + port +
          " --mqtt-prefix bench/fleet --fleet --duration 600",
      "/dev/null", (work / "recorder.log").string());
  std::this_thread::sleep_for(std::chrono::seconds(3));  // its retained messages in
  // GET `path` five times, half a second apart: the median time in ms and
  // the size of the answer (kept in fleet.json).
  auto askFiveTimes = [&](const std::string& path) -> std::pair<double, double> {
    std::string ask =
        "curl -s -o " + (work / "fleet.json").string() +
        " -w '%{time_total} %{size_download}' http://127.0.0.1:" + std::to_string(httpPort) + path;
    std::vector<double> asked;
    double bytes = 0;
    for (int i = 0; i < 5; ++i) {
      FILE* out = popen(ask.c_str(), "r");
      double time = 0;
      if (out && std::fscanf(out, "%lf %lf", &time, &bytes) == 2) asked.push_back(time);
      if (out) pclose(out);
      std::this_thread::sleep_for(std::chrono::milliseconds(500));
    }
    std::sort(asked.begin(), asked.end());
    return {asked.empty() ? 0.0 : asked[asked.size() / 2] * 1000, bytes};
  };
  // A page of the whole fleet a recorder at a time (fleet_view.js): the
  // recorders with their counts, and one recorder's cameras.
  auto counts = askFiveTimes("/api/fleet?cameras=false");
  auto one = askFiveTimes("/api/fleet?recorder=bench-recorder-0");
  // The page's search: a vehicle's serial (here on a camera of each recorder).
  auto found = askFiveTimes("/api/fleet?match=S217");
  std::pair<double, double> whole;
  double fleetCpu =
      measure("wirc-recorder --fleet", recorder, [&] { whole = askFiveTimes("/api/fleet"); });
  auto view = nlohmann::json::parse(std::ifstream(work / "fleet.json"), nullptr, false);
  size_t seen = 0, live = 0, online = 0;
  if (view.is_object())
    for (const auto& r : view.value("recorders", nlohmann::json::array())) {
      if (!r.value("id", "").starts_with("bench-recorder-")) continue;
      ++seen;
      online += r.value("online", false) ? 1 : 0;
      for (const auto& c : r["cameras"]) live += c.value("state", "") == "live" ? 1 : 0;
    }
  std::printf("wirc-recorder --fleet: %.2fx the stock reader's CPU\n",
              stockCpu > 0 ? fleetCpu / stockCpu : 0.0);
  std::printf(
      "GET /api/fleet: %.0f ms (median of 5), %.1f MB; %zu of %d recorders online, "
      "%zu of %d cameras live\n",
      whole.first, whole.second / 1e6, online, recorders, live, recorders * cameras);
  std::printf("GET /api/fleet?cameras=false: %.0f ms, %.1f kB (%.3fx the whole's time)\n",
              counts.first, counts.second / 1e3, whole.first > 0 ? counts.first / whole.first : 0);
  std::printf("GET /api/fleet?recorder=ID: %.0f ms, %.1f kB (%.3fx the whole's time)\n", one.first,
              one.second / 1e3, whole.first > 0 ? one.first / whole.first : 0);
  std::printf("GET /api/fleet?match=S217: %.0f ms, %.1f kB (%.3fx the whole's time)\n", found.first,
              found.second / 1e3, whole.first > 0 ? found.first / whole.first : 0);
  uint64_t dropped = 0;
  for (const auto& member : fleet) dropped += member.client->stats().dropped;
  std::printf("statuses dropped by the simulated recorders' clients (unsent over %llu): %llu\n",
              static_cast<unsigned long long>(MqttClient::kMaxUnsent),
              static_cast<unsigned long long>(dropped));
  stopGroup(recorder, SIGINT);
  publishing = false;
  publisher.join();
  fleet.clear();
  stopGroup(broker, SIGTERM);
  fs::remove_all(work);
  return 0;
}
