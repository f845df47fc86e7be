#include "export/fleet_fetch.h"

#include <glib.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstdio>
#include <mutex>
#include <nlohmann/json.hpp>
#include <thread>

#include "export/exporter.h"
#include "export/http_fetcher.h"
#include "fleet/fleet_announcement.h"
#include "fleet/fleet_directory.h"
#include "fleet/mqtt_client.h"
#include "record/recording_index.h"
#include "recording/segment_selection.h"

namespace wircam::recorder {

namespace fs = std::filesystem;
using Json = nlohmann::json;
using Clock = std::chrono::steady_clock;
using std::chrono::milliseconds;

namespace {

int64_t unixMsNow() { return g_get_real_time() / 1000; }

// Why the MQTT client could not connect, from its log line (which goes
// on about the recorder's retrying): " (Connection refused)".
std::string brokersWord(const std::string& line) {
  auto open = line.find('('), close = line.find(')', open);
  if (open == std::string::npos || close == std::string::npos) return "";
  return " " + line.substr(open, close - open + 1);
}

// The recorders announced on the broker, as a fleet recorder sees them
// (GET /api/fleet's "recorders"), once the retained messages are in: 300 ms
// after the last one, and at least 1 s after the connection.
Expected<Json, std::string> announcedRecorders(const MqttUrl& broker) {
  FleetDirectory directory;
  std::mutex lock;
  std::condition_variable heard;
  std::optional<Clock::time_point> connectedAt;
  Clock::time_point lastMessage = Clock::now();
  std::string lastWord;
  MqttClient::Handlers handlers;
  std::atomic<MqttClient*> self{nullptr};
  handlers.connected = [&](MqttClient& client) {
    self = &client;
    client.subscribe(std::string(kFleetTopicRoot) + "+");
    std::lock_guard guard(lock);
    connectedAt = Clock::now();
    heard.notify_all();
  };
  handlers.message = [&](const std::string& topic, const std::string& payload, bool) {
    if (topic.starts_with(kFleetTopicRoot)) {
      // Whether it is still there: its prefix's will.
      if (auto prefix = directory.announced(topic, payload, unixMsNow()))
        if (MqttClient* client = self) client->subscribe(*prefix + "/available");
    } else {
      directory.heard(topic, payload, unixMsNow());
    }
    std::lock_guard guard(lock);
    lastMessage = Clock::now();
  };
  handlers.log = [&](const std::string& line) {
    std::lock_guard guard(lock);
    lastWord = line;
  };
  auto client =
      MqttClient::start(broker, "wirc-export-" + std::to_string(getpid()), {}, std::move(handlers));
  if (!client) return unexpected(client.error());
  std::unique_lock guard(lock);
  if (!heard.wait_for(guard, std::chrono::seconds(10), [&] { return connectedAt.has_value(); }))
    return unexpected("cannot reach the fleet's broker " + broker.host + ":" +
                      std::to_string(broker.port) + " within 10 s" + brokersWord(lastWord));
  while (true) {
    auto now = Clock::now();
    if (now - *connectedAt >= milliseconds(1000) && now - lastMessage >= milliseconds(300)) break;
    if (now - *connectedAt >= milliseconds(10000)) break;  // a chatty broker: enough
    guard.unlock();
    std::this_thread::sleep_for(milliseconds(50));
    guard.lock();
  }
  guard.unlock();
  return directory.view().value("recorders", Json::array());
}

bool overlaps(const Json& entry, const FleetFetchRequest& request) {
  auto begins = parseIsoTime(entry.value("start_utc", ""));
  if (!begins) return false;
  auto lasts = static_cast<int64_t>(entry.value("duration_s", 0.0) * 1e9);
  return !(request.end && *begins > *request.end) &&
         !(request.start && *begins + lasts < *request.start);
}

}  // namespace

Expected<FleetFetchReport, std::string> fetchFromFleet(const FleetFetchRequest& request,
                                                       const FleetFetchProgress& progress) {
  auto say = [&](const std::string& line) { return !progress || progress(line); };
  auto recorders = announcedRecorders(request.broker);
  if (!recorders) return unexpected(recorders.error());
  if (recorders->empty())
    return unexpected("no recorder is announced on " + request.broker.host + ":" +
                      std::to_string(request.broker.port) + " (wircam-fleet/recorders/+)");
  HttpFetcher fetcher(request.token);
  FleetFetchReport report;
  struct Wanted {
    Json entry;
    std::string base;      // the recorder's HTTP URL, ending in '/'
    std::string recorder;  // its id
  };
  std::vector<Wanted> wanted;
  std::string suffix = "-" + request.camera;
  std::string vehicleName;
  report.announced = recorders->size();
  for (const auto& recorder : *recorders) {
    std::string name = recorder.value("host", "") + " (" + recorder.value("id", "") + ")";
    if (!recorder.value("online", false)) {
      report.notes.push_back("recorder " + name + " is offline (last seen " +
                             recorder.value("last_seen_utc", "?") +
                             "): what it holds is not in the export");
      continue;
    }
    std::string base = recorder["urls"].value("http", "");
    if (base.empty()) {
      report.notes.push_back("recorder " + name + " serves no HTTP: left out");
      continue;
    }
    if (!base.ends_with('/')) base += '/';
    gchar* vehicle = g_uri_escape_string(request.vehicle.c_str(), nullptr, FALSE);
    auto list = fetcher.json(base + "api/recordings?vehicle=" + vehicle);
    g_free(vehicle);
    if (!list) {
      report.notes.push_back("recorder " + name + ": " + list.error() + ": left out");
      continue;
    }
    ++report.asked;
    size_t before = wanted.size();
    for (const auto& entry : *list) {
      if (!entry.value("camera", "").ends_with(suffix) || !overlaps(entry, request)) continue;
      if (vehicleName.empty() && entry.contains("vehicle") && entry["vehicle"].is_object())
        vehicleName = entry["vehicle"].value("name", "");
      wanted.push_back({entry, base, recorder.value("id", "")});
    }
    if (wanted.size() > before) ++report.holders;
  }
  if (wanted.empty()) {
    std::string why = "no recorder of the fleet holds " + request.camera + " of vehicle " +
                      request.vehicle + " in that range (" + std::to_string(report.asked) +
                      " asked)";
    for (const auto& note : report.notes) why += "; " + note;
    return unexpected(why);
  }
  std::sort(wanted.begin(), wanted.end(), [](const Wanted& a, const Wanted& b) {
    return *parseIsoTime(a.entry["start_utc"]) < *parseIsoTime(b.entry["start_utc"]);
  });

  // One camera in the folder, whichever recorder named it what; each
  // segment under its place in time (two recorders may start one in the
  // same second, while the vehicle moves from one to the other).
  report.camera = fileNamePart(vehicleName.empty() ? request.vehicle : vehicleName) + suffix;
  std::error_code error;
  fs::create_directories(request.folder, error);
  if (error) return unexpected("cannot make " + request.folder.string() + ": " + error.message());
  RecordingIndex index(request.folder);
  for (size_t i = 0; i < wanted.size(); ++i) {
    const auto& [entry, base, recorder] = wanted[i];
    std::string file = entry.value("file", "");
    std::string stem = report.camera + "-" + compactTimeOf(*parseIsoTime(entry["start_utc"])) +
                       "-" + std::to_string(i + 1);
    std::string extension = fs::path(file).extension().string();  // .mkv or .mp4
    std::string path = entry.value("url", "");
    std::string url = base + path.substr(path.starts_with("/") ? 1 : 0);
    if (!say("fetching " + std::to_string(i + 1) + " of " + std::to_string(wanted.size()) + ": " +
             file + " from " + base))
      return unexpected(std::string("stopped"));
    if (auto problem = fetcher.download(url, request.folder / (stem + extension)))
      return unexpected("cannot fetch " + *problem);
    std::string sidecar = url.substr(0, url.rfind('.')) + ".jsonl";
    if (auto problem = fetcher.download(sidecar, request.folder / (stem + ".jsonl"), true))
      return unexpected("cannot fetch " + *problem);
    IndexEntry indexed;
    indexed.camera = report.camera;
    indexed.file = stem + extension;
    indexed.startUtc = entry.value("start_utc", "");
    indexed.durationSeconds = entry.value("duration_s", 0.0);
    indexed.frames = entry.value("frames", uint64_t{0});
    indexed.bytes = fs::file_size(request.folder / indexed.file, error);
    indexed.vehicle = entry.value("vehicle", Json());
    indexed.recorder = recorder;
    report.bytes += indexed.bytes;
    index.add(std::move(indexed));
    ++report.segments;
  }
  if (!index.save()) return unexpected("cannot write " + index.path().string());
  return report;
}

}  // namespace wircam::recorder
