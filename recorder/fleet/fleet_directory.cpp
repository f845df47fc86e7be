#include "fleet/fleet_directory.h"

#include <algorithm>
#include <cctype>
#include <string_view>
#include <tuple>

#include "record/segment_planner.h"

namespace wircam::recorder {

std::optional<std::string> FleetDirectory::announced(const std::string& topic,
                                                     const std::string& payload,
                                                     int64_t nowUnixMs) {
  if (!topic.starts_with(kFleetTopicRoot)) return std::nullopt;
  std::string id = topic.substr(std::string(kFleetTopicRoot).size());
  std::lock_guard lock(mutex_);
  if (payload.empty()) {
    recorders_.erase(id);
    return std::nullopt;
  }
  auto announcement = announcementOf(payload);
  if (!announcement || announcement->id != id) return std::nullopt;
  bool knownPrefix = std::any_of(recorders_.begin(), recorders_.end(), [&](const auto& r) {
    return r.second.announcement.mqttPrefix == announcement->mqttPrefix;
  });
  auto& recorder = recorders_[id];
  recorder.announcement = std::move(*announcement);
  // A retained announcement is as old as it says; a fresh one is now.
  recorder.lastSeenUnixMs = std::max(recorder.lastSeenUnixMs, recorder.announcement.seenUnixMs);
  if (online(recorder)) recorder.lastSeenUnixMs = nowUnixMs;
  if (knownPrefix) return std::nullopt;
  return recorder.announcement.mqttPrefix;
}

FleetDirectory::Recorder* FleetDirectory::ownerOf(const std::string& topic, std::string& rest) {
  // One pass: this runs for every status of every camera of the fleet.
  Recorder* owner = nullptr;
  size_t longest = 0;
  for (auto& [id, recorder] : recorders_) {
    const auto& a = recorder.announcement;
    const auto& prefix = a.mqttPrefix;
    if (topic.size() <= prefix.size() || !topic.starts_with(prefix) ||
        topic[prefix.size()] != '/' || prefix.size() < longest)
      continue;
    if (!owner || prefix.size() > longest ||
        std::tie(a.seenUnixMs, a.id) >
            std::tie(owner->announcement.seenUnixMs, owner->announcement.id)) {
      owner = &recorder;
      longest = prefix.size();
    }
  }
  if (owner) rest = topic.substr(longest + 1);
  return owner;
}

bool FleetDirectory::superseded(const Recorder& recorder) const {
  const auto& mine = recorder.announcement;
  return std::any_of(recorders_.begin(), recorders_.end(), [&](const auto& other) {
    const auto& theirs = other.second.announcement;
    return theirs.mqttPrefix == mine.mqttPrefix &&
           (theirs.seenUnixMs > mine.seenUnixMs ||
            (theirs.seenUnixMs == mine.seenUnixMs && theirs.id > mine.id));
  });
}

bool FleetDirectory::online(const Recorder& recorder) const {
  auto available = available_.find(recorder.announcement.mqttPrefix);
  return available != available_.end() && available->second && !superseded(recorder);
}

bool FleetDirectory::heard(const std::string& topic, const std::string& payload,
                           int64_t nowUnixMs) {
  std::lock_guard lock(mutex_);
  std::string rest;
  Recorder* recorder = ownerOf(topic, rest);
  if (!recorder) return false;
  if (rest == "available") {
    bool nowOnline = payload == "online";
    // (The owner is the newest on its prefix: online is the prefix's word.)
    if (nowOnline || available_[recorder->announcement.mqttPrefix])
      recorder->lastSeenUnixMs = nowUnixMs;
    available_[recorder->announcement.mqttPrefix] = nowOnline;
    return true;
  }
  auto slash = rest.find('/');
  if (slash == std::string::npos || rest.substr(slash + 1) != "status") return false;
  auto status = nlohmann::json::parse(payload, nullptr, false);
  if (!status.is_object()) return false;
  recorder->statuses[rest.substr(0, slash)] = std::move(status);
  if (available_[recorder->announcement.mqttPrefix]) recorder->lastSeenUnixMs = nowUnixMs;
  return true;
}

std::vector<std::string> FleetDirectory::prefixes() const {
  std::lock_guard lock(mutex_);
  std::vector<std::string> all;
  for (const auto& [id, recorder] : recorders_)
    if (std::find(all.begin(), all.end(), recorder.announcement.mqttPrefix) == all.end())
      all.push_back(recorder.announcement.mqttPrefix);
  return all;
}

namespace {

// Whether any of `fields` holds `needle`, case aside (ASCII: names,
// serials and hosts), without a copy of each (a search of 25,600 cameras).
bool holds(std::initializer_list<std::string_view> fields, std::string_view needle) {
  auto same = [](char a, char b) {
    return std::tolower(static_cast<unsigned char>(a)) ==
           std::tolower(static_cast<unsigned char>(b));
  };
  return std::any_of(fields.begin(), fields.end(), [&](std::string_view field) {
    return std::search(field.begin(), field.end(), needle.begin(), needle.end(), same) !=
           field.end();
  });
}

}  // namespace

nlohmann::json FleetDirectory::view(const FleetViewScope& scope) const {
  std::lock_guard lock(mutex_);
  std::vector<const Recorder*> ordered;
  for (const auto& [id, recorder] : recorders_)
    if (!scope.recorder || *scope.recorder == id) ordered.push_back(&recorder);
  std::stable_sort(ordered.begin(), ordered.end(),
                   [](auto* a, auto* b) { return a->announcement.host < b->announcement.host; });
  std::string needle = scope.match.value_or("");
  nlohmann::json recorders = nlohmann::json::array();
  for (const Recorder* r : ordered) {
    const auto& a = r->announcement;
    bool recorderMatches = scope.match && holds({a.host, a.id}, needle);
    nlohmann::json cameras = nlohmann::json::array();
    size_t live = 0;
    for (const auto& c : a.cameras) {
      auto status = r->statuses.find(c.name);
      // What its recorder last said; a recorder offline says nothing now.
      std::string state = online(*r) && status != r->statuses.end()
                              ? status->second.value("state", "unknown")
                              : "unknown";
      live += state == "live" ? 1 : 0;
      if (!scope.cameras) continue;
      if (scope.match && !recorderMatches &&
          !holds({c.name, c.vehicle ? c.vehicle->name : "", c.vehicle ? c.vehicle->serial : ""},
                 needle))
        continue;
      cameras.push_back(
          {{"name", c.name},
           {"vehicle", toJson(c.vehicle)},
           {"rtsp_path", c.rtspPath},
           {"state", state},
           {"status", status != r->statuses.end() ? status->second : nlohmann::json()}});
    }
    if (scope.match && cameras.empty() && !recorderMatches) continue;
    nlohmann::json entry = toJson(a);
    entry.erase("seen_utc");
    entry.erase("seen_unix_ms");
    entry["online"] = online(*r);
    entry["last_seen_utc"] = SegmentPlanner::isoUtc(r->lastSeenUnixMs);
    entry["camera_count"] = a.cameras.size();
    entry["cameras_live"] = live;
    if (scope.cameras)
      entry["cameras"] = std::move(cameras);
    else
      entry.erase("cameras");  // the announcement's own list
    recorders.push_back(std::move(entry));
  }
  return {{"recorders", recorders}};
}

}  // namespace wircam::recorder
