// The fleet as one recorder sees it (--fleet): every recorder announced on
// the broker, online or when it was last seen, and its cameras' states from
// their retained statuses. Fed from the MQTT client's thread, read from the
// main loop's: thread-safe.
#pragma once

#include <cstdint>
#include <map>
#include <mutex>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "fleet/fleet_announcement.h"

namespace wircam::recorder {

// What GET /api/fleet asks for: the whole fleet, one recorder, or the
// recorders without their cameras (a fleet of thousands of cameras is
// shown a recorder at a time).
struct FleetViewScope {
  std::optional<std::string> recorder;  // by id: that one alone
  bool cameras = true;                  // false: each recorder's camera counts only
  // Only the cameras whose name, vehicle name or serial, or recorder's host
  // or id holds this (case aside), and only the recorders that have one.
  std::optional<std::string> match;
};

class FleetDirectory {
 public:
  // A message on wircam-fleet/recorders/ID; the recorder's MQTT prefix when
  // it is one not heard of before (its topics are then to be subscribed to).
  // An empty payload forgets the recorder (a retired one, cleared by hand).
  std::optional<std::string> announced(const std::string& topic, const std::string& payload,
                                       int64_t nowUnixMs);
  // A message under an announced recorder's prefix: PREFIX/available or
  // PREFIX/STREAM/status. False when it is neither.
  bool heard(const std::string& topic, const std::string& payload, int64_t nowUnixMs);

  // The prefixes to subscribe to again after a new connection.
  std::vector<std::string> prefixes() const;
  // GET /api/fleet: {"recorders": [...]}, by host, then id; each with its
  // camera_count and cameras_live, and its cameras unless left out.
  nlohmann::json view(const FleetViewScope& scope = {}) const;

 private:
  struct Recorder {
    Announcement announcement;
    int64_t lastSeenUnixMs = 0;
    std::map<std::string, nlohmann::json> statuses;  // by camera
  };
  // The recorder a topic is about: the longest prefix it is under and, of
  // recorders announced on one prefix (one came back with a new id, its
  // folder replaced), the newest; the others are superseded.
  Recorder* ownerOf(const std::string& topic, std::string& rest);
  bool superseded(const Recorder& recorder) const;
  bool online(const Recorder& recorder) const;

  mutable std::mutex mutex_;
  std::map<std::string, Recorder> recorders_;  // by id
  // PREFIX/available, by prefix: a prefix's will is one topic, whoever
  // announced on it.
  std::map<std::string, bool> available_;
};

}  // namespace wircam::recorder
