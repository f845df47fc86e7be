#include "fleet/fleet_announcement.h"

#include "record/segment_planner.h"

namespace wircam::recorder {

namespace {

struct UrlParts {
  std::string scheme;  // "http://"
  std::string host;
  std::string rest;  // ":8080/..."
};

UrlParts partsOf(const std::string& url) {
  auto scheme = url.find("://");
  size_t hostAt = scheme == std::string::npos ? 0 : scheme + 3;
  size_t hostEnd = hostAt;
  if (hostAt < url.size() && url[hostAt] == '[')
    hostEnd = url.find(']', hostAt) == std::string::npos ? url.size() : url.find(']', hostAt) + 1;
  else
    hostEnd = std::min(url.find_first_of(":/", hostAt), url.size());
  return {url.substr(0, hostAt), url.substr(hostAt, hostEnd - hostAt), url.substr(hostEnd)};
}

bool isWildcard(const std::string& host) {
  return host == "0.0.0.0" || host == "[::]" || host == "::" || host.empty();
}

std::string text(const nlohmann::json& j, const char* key) {
  auto found = j.find(key);
  return found != j.end() && found->is_string() ? found->get<std::string>() : "";
}

}  // namespace

std::string announcementTopic(const std::string& recorderId) {
  return kFleetTopicRoot + recorderId;
}

nlohmann::json toJson(const Announcement& a) {
  nlohmann::json cameras = nlohmann::json::array();
  for (const auto& c : a.cameras)
    cameras.push_back(
        {{"name", c.name}, {"vehicle", toJson(c.vehicle)}, {"rtsp_path", c.rtspPath}});
  return {{"id", a.id},
          {"host", a.host},
          {"version", a.version},
          {"mqtt_prefix", a.mqttPrefix},
          {"urls", {{"http", a.http}, {"rtsp", a.rtsp}, {"foxglove", a.foxglove}}},
          {"webrtc", a.webrtc},
          {"cameras", cameras},
          {"seen_utc", SegmentPlanner::isoUtc(a.seenUnixMs)},
          {"seen_unix_ms", a.seenUnixMs}};
}

std::optional<Announcement> announcementOf(const std::string& payload) {
  auto j = nlohmann::json::parse(payload, nullptr, false);
  if (!j.is_object() || text(j, "id").empty() || text(j, "mqtt_prefix").empty())
    return std::nullopt;
  Announcement a{.id = text(j, "id"),
                 .host = text(j, "host"),
                 .version = text(j, "version"),
                 .mqttPrefix = text(j, "mqtt_prefix")};
  if (auto urls = j.find("urls"); urls != j.end() && urls->is_object()) {
    a.http = text(*urls, "http");
    a.rtsp = text(*urls, "rtsp");
    a.foxglove = text(*urls, "foxglove");
  }
  a.webrtc = j.value("webrtc", false) == true;
  if (auto cameras = j.find("cameras"); cameras != j.end() && cameras->is_array())
    for (const auto& c : *cameras)
      if (c.is_object() && !text(c, "name").empty())
        a.cameras.push_back({text(c, "name"), vehicleOf(c.value("vehicle", nlohmann::json())),
                             text(c, "rtsp_path")});
  if (auto seen = j.find("seen_unix_ms"); seen != j.end() && seen->is_number_integer())
    a.seenUnixMs = seen->get<int64_t>();
  return a;
}

std::string fleetHttpUrl(const std::string& listening, const std::string& fleetUrl,
                         const std::string& hostName) {
  if (!fleetUrl.empty()) return fleetUrl.ends_with("/") ? fleetUrl : fleetUrl + "/";
  return fleetServiceUrl(listening, fleetUrl, hostName);
}

std::string fleetServiceUrl(const std::string& listening, const std::string& fleetUrl,
                            const std::string& hostName) {
  if (listening.empty()) return "";
  auto parts = partsOf(listening);
  if (!fleetUrl.empty())
    parts.host = partsOf(fleetUrl).host;
  else if (isWildcard(parts.host))
    parts.host = hostName;
  return parts.scheme + parts.host + parts.rest;
}

}  // namespace wircam::recorder
