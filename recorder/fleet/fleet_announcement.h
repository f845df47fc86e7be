// What a recorder tells the fleet about itself, retained on the broker at
// wircam-fleet/recorders/ID: who it is, where others reach it, its cameras
// and their vehicles. Its `PREFIX/available` (online, or offline as its last
// will) and its cameras' retained `PREFIX/STREAM/status` say the rest: the
// fleet is composed of topics each recorder publishes anyway.
#pragma once

#include <cstdint>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "fleet/vehicle_identity.h"

namespace wircam::recorder {

inline constexpr const char* kFleetTopicRoot = "wircam-fleet/recorders/";
// Commands for a vehicle, by its serial, whichever recorder holds it:
// wircam-fleet/vehicles/SERIAL/follow/set and .../target/set (mqtt.md's
// payloads). The recorder whose camera sees the vehicle obeys; the others
// are silent.
inline constexpr const char* kVehicleTopicRoot = "wircam-fleet/vehicles/";

struct AnnouncedCamera {
  std::string name;  // the stream, "<device>-cam<N>": unique within its recorder only
  std::optional<VehicleIdentity> vehicle;
  std::string rtspPath;  // "/<device>/cam<N>"; empty without an RTSP server
};

struct Announcement {
  std::string id;  // recorder_id.h
  std::string host;
  std::string version;
  std::string mqttPrefix;
  // Base URLs others use (empty: not served): "http://H:P/", "rtsp://H:P",
  // "ws://H:P/"; WebRTC's WHEP is under the HTTP one when `webrtc`.
  std::string http, rtsp, foxglove;
  bool webrtc = false;
  std::vector<AnnouncedCamera> cameras;
  int64_t seenUnixMs = 0;  // when it was said
};

std::string announcementTopic(const std::string& recorderId);
nlohmann::json toJson(const Announcement& announcement);
// A payload another recorder sent, checked: nullopt when it is not one.
std::optional<Announcement> announcementOf(const std::string& payload);

// The URL others should use for a server listening at `listening`
// ("http://0.0.0.0:8080/"): with --fleet-url, its scheme, host and port for
// HTTP and its host for the others; else a wildcard host is replaced by
// this machine's name.
std::string fleetHttpUrl(const std::string& listening, const std::string& fleetUrl,
                         const std::string& hostName);
std::string fleetServiceUrl(const std::string& listening, const std::string& fleetUrl,
                            const std::string& hostName);

}  // namespace wircam::recorder
