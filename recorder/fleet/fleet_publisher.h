// The recorder's MQTT topics (see wirc-recorder --help): availability with a
// last will, each stream's retained status (on change, at least every 5 s),
// its detections (rate-limited) and events, and the follow/target commands
// it takes; with discovery, Home Assistant's configs and the snapshots its
// camera entity shows; the fleet's vehicle commands for the vehicles it
// holds; the recorder's announcement to the fleet and, with
// --fleet, the fleet's directory (fleet_directory.h). Everything here runs on the GLib main loop; commands arrive on
// the MQTT client's thread and are handed over to it.
#pragma once

#include <glib.h>

#include <chrono>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "common/expected.h"
#include "fleet/fleet_announcement.h"
#include "fleet/fleet_command.h"
#include "fleet/fleet_directory.h"
#include "fleet/home_assistant.h"
#include "fleet/mqtt_client.h"

namespace wircam::recorder {

class FleetPublisher {
 public:
  static constexpr std::chrono::seconds kStatusInterval{5};

  struct Settings {
    MqttUrl url;
    std::string prefix;
    double detectionsRate = 0;  // per second and stream; 0 = every frame
    std::vector<std::string> streams;
    // Home Assistant's discovery (--mqtt-discovery), or none.
    std::optional<DiscoveryNames> discovery;
    // --fleet: follow every recorder's announcement and statuses.
    bool fleet = false;
  };
  // `apply` runs on the main loop for each valid live command.
  static Expected<std::unique_ptr<FleetPublisher>, std::string> start(
      const Settings& settings, std::function<void(const FleetCommand&)> apply);
  // Says offline (retained) and disconnects, bounded.
  ~FleetPublisher();

  // Publishes when it differs from the last one, or kStatusInterval passed.
  void status(const std::string& stream, const nlohmann::json& status, bool force = false);
  void detections(const std::string& stream, const nlohmann::json& message, bool anyTags);
  void event(const std::string& stream, const nlohmann::json& event);
  // A camera's newest frame (JPEG bytes), retained on PREFIX/STREAM/snapshot.
  void snapshot(const std::string& stream, const std::string& jpeg);
  // The cameras a reload left (Home Assistant's configs follow).
  void setStreams(const std::vector<std::string>& streams);
  // A command for a vehicle wherever it is (wircam-fleet/vehicles/SERIAL/
  // COMMAND, not retained): the recorder holding it applies it, this one
  // too. Whether it was handed to the broker.
  bool commandVehicle(const std::string& serial, const std::string& command,
                      const std::string& payload);
  // Retained at wircam-fleet/recorders/ID, now and at each connection.
  void announce(const Announcement& announcement);
  // With --fleet: the fleet as the broker tells it; else null.
  const FleetDirectory* directory() const { return settings_.fleet ? &directory_ : nullptr; }
  MqttClient::Stats stats() const { return client_->stats(); }
  bool connected() const { return client_->connected(); }

 private:
  struct StreamState {
    std::string lastStatus;
    std::chrono::steady_clock::time_point statusAt{};
    std::chrono::steady_clock::time_point detectionsAt{};
    bool hadTags = false;
  };
  FleetPublisher(Settings settings, std::function<void(const FleetCommand&)> apply);
  std::string topic(const std::string& stream, const char* leaf) const;
  void onMessage(const std::string& topic, const std::string& payload, bool retained);
  void republish(MqttClient& client);
  // Its availability and statuses: the fleet directory's view of it.
  void follow(MqttClient& client, const std::string& prefix);
  // A message of the fleet (announcements, others' availability and
  // statuses), taken in; false when it is not one.
  bool fleetMessage(const std::string& topic, const std::string& payload);
  // Whether the message was a discovery config (cleared if stale).
  bool clearedStaleConfig(const std::string& topic, const std::string& payload);

  std::vector<std::string> streamNames() const;

  const Settings settings_;  // its streams: the first ones
  const std::function<void(const FleetCommand&)> apply_;
  mutable std::mutex namesMutex_;  // the MQTT thread reads the names
  std::vector<std::string> names_;
  std::unique_ptr<MqttClient> client_;
  // The client as the MQTT thread knows it (from its first connection on):
  // messages may come before start() has stored client_.
  MqttClient* sessionClient_ = nullptr;
  std::map<std::string, StreamState> streams_;  // main loop only (the MQTT thread reads settings_)
  // The retained statuses, for a new connection (guarded: the MQTT thread reads it).
  std::mutex retainedMutex_;
  std::map<std::string, std::string> retained_;
  std::string announcementTopic_, announcement_;       // guarded likewise
  std::map<std::string, std::string> vehicleStreams_;  // serial → its steering camera; likewise
  FleetDirectory directory_;
};

}  // namespace wircam::recorder
