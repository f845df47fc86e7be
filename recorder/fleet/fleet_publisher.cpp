#include "fleet/fleet_publisher.h"

#include <unistd.h>

#include <algorithm>
#include <cstdio>

#include "log_line.h"

namespace wircam::recorder {

FleetPublisher::FleetPublisher(Settings settings, std::function<void(const FleetCommand&)> apply)
    : settings_(std::move(settings)), apply_(std::move(apply)), names_(settings_.streams) {
  for (const auto& stream : settings_.streams) streams_[stream];
}

std::vector<std::string> FleetPublisher::streamNames() const {
  std::lock_guard lock(namesMutex_);
  return names_;
}

void FleetPublisher::setStreams(const std::vector<std::string>& streams) {
  auto before = streamNames();
  {
    std::lock_guard lock(namesMutex_);
    names_ = streams;
  }
  for (const auto& stream : streams) streams_[stream];
  // A camera gone (moved to another recorder by a reload) leaves no
  // retained status saying it is live here.
  for (const auto& stream : before)
    if (std::find(streams.begin(), streams.end(), stream) == streams.end() && client_) {
      {
        std::lock_guard lock(retainedMutex_);
        retained_.erase(stream);
      }
      client_->publish(topic(stream, "status"), "", true, 1);
    }
  if (!settings_.discovery || !client_) return;
  // Home Assistant learns of a camera added, and forgets one removed.
  for (const auto& stream : streams)
    if (std::find(before.begin(), before.end(), stream) == before.end())
      for (const auto& [configTopic, config] : discoveryConfigs(*settings_.discovery, stream))
        client_->publish(configTopic, config, true, 1);
  for (const auto& stream : before)
    if (std::find(streams.begin(), streams.end(), stream) == streams.end()) {
      streams_.erase(stream);
      for (const auto& [configTopic, config] : discoveryConfigs(*settings_.discovery, stream))
        client_->publish(configTopic, "", true, 1);
    }
}

Expected<std::unique_ptr<FleetPublisher>, std::string> FleetPublisher::start(
    const Settings& settings, std::function<void(const FleetCommand&)> apply) {
  std::unique_ptr<FleetPublisher> publisher(new FleetPublisher(settings, std::move(apply)));
  auto* self = publisher.get();
  char host[256] = "host";
  gethostname(host, sizeof host - 1);
  std::string clientId = "wirc-recorder-" + std::string(host) + "-" + std::to_string(getpid());
  MqttWill will{settings.prefix + "/available", "offline"};
  auto client = MqttClient::start(
      settings.url, clientId, will,
      {.connected = [self](MqttClient& connected) { self->republish(connected); },
       .message = [self](const std::string& topic, const std::string& payload,
                         bool retained) { self->onMessage(topic, payload, retained); },
       .log = [](const std::string& line) { logLine(line); }});
  if (!client) return unexpected(client.error());
  publisher->client_ = std::move(*client);
  return publisher;
}

FleetPublisher::~FleetPublisher() {
  client_.reset();  // says offline
}

std::string FleetPublisher::topic(const std::string& stream, const char* leaf) const {
  return settings_.prefix + "/" + stream + "/" + leaf;
}

// On the MQTT thread, at each connection: what we listen to, what we know,
// who we are, and last that we are online. The broker takes a client's
// packets in order, so whoever sees "online" finds our subscriptions in
// place: a command sent on seeing it was lost when "online" went first
// (a test under load found the recorder deaf to three commands).
void FleetPublisher::republish(MqttClient& client) {
  sessionClient_ = &client;
  if (settings_.fleet) {
    client.subscribe(std::string(kFleetTopicRoot) + "+");
    for (const auto& prefix : directory_.prefixes()) follow(client, prefix);
  }
  for (const char* command : {"follow/set", "target/set", "drive/set"}) {
    client.subscribe(settings_.prefix + "/+/" + command);
    client.subscribe(std::string(kVehicleTopicRoot) + "+/" + command);
  }
  // Our earlier configs come back retained: those of cameras gone are cleared.
  if (settings_.discovery) client.subscribe(discoverySubscription(*settings_.discovery));
  {
    std::lock_guard lock(retainedMutex_);
    for (const auto& [stream, status] : retained_)
      client.publish(topic(stream, "status"), status, true);
    if (!announcement_.empty()) client.publish(announcementTopic_, announcement_, true, 1);
  }
  if (settings_.discovery)
    for (const auto& stream : streamNames())
      for (const auto& [configTopic, config] : discoveryConfigs(*settings_.discovery, stream))
        client.publish(configTopic, config, true, 1);
  client.publish(settings_.prefix + "/available", "online", true, 1);
}

// A retained config of this recorder for a camera it no longer has: an
// empty retained message removes it from Home Assistant.
bool FleetPublisher::clearedStaleConfig(const std::string& topicName, const std::string& payload) {
  if (!settings_.discovery || !topicName.starts_with(settings_.discovery->discoveryPrefix + "/"))
    return false;
  if (!payload.empty() && isStaleConfig(*settings_.discovery, topicName, streamNames())) {
    sessionClient_->publish(topicName, "", true, 1);
    logLine("cleared the Home Assistant config " + printableText(topicName) +
            " (a camera no longer here)");
  }
  return true;
}

void FleetPublisher::follow(MqttClient& client, const std::string& prefix) {
  client.subscribe(prefix + "/available");
  client.subscribe(prefix + "/+/status");
}

bool FleetPublisher::commandVehicle(const std::string& serial, const std::string& command,
                                    const std::string& payload) {
  return client_->publish(kVehicleTopicRoot + serial + "/" + command, payload);
}

bool FleetPublisher::fleetMessage(const std::string& topicName, const std::string& payload) {
  if (!settings_.fleet) return false;
  int64_t now = g_get_real_time() / 1000;
  if (topicName.starts_with(kFleetTopicRoot)) {
    if (auto prefix = directory_.announced(topicName, payload, now))
      follow(*sessionClient_, *prefix);
    return true;
  }
  return directory_.heard(topicName, payload, now);
}

void FleetPublisher::onMessage(const std::string& topicName, const std::string& payload,
                               bool retained) {
  if (clearedStaleConfig(topicName, payload) || fleetMessage(topicName, payload)) return;
  // PREFIX/STREAM/follow/set: the stream is the level after the prefix;
  // wircam-fleet/vehicles/SERIAL/follow/set: the vehicle's steering camera.
  bool forVehicle = topicName.starts_with(kVehicleTopicRoot);
  size_t root = forVehicle ? std::string(kVehicleTopicRoot).size() : settings_.prefix.size() + 1;
  std::string rest = topicName.substr(std::min(topicName.size(), root));
  auto slash = rest.find('/');
  std::string stream = rest.substr(0, slash);
  std::string command = slash == std::string::npos ? "" : rest.substr(slash + 1);
  if (forVehicle) {
    std::lock_guard lock(retainedMutex_);
    auto held = vehicleStreams_.find(stream);
    if (held == vehicleStreams_.end()) return;  // another recorder's vehicle, or none
    stream = held->second;
  }
  if (payload.empty()) return;  // clearing a retained command: nothing to do
  if (retained) {
    // A command is an act, not a state: one left retained would replay at
    // every restart.
    std::string shown = printableText(topicName);
    logLine("ignoring the retained message on " + shown +
            " (commands are not retained; clear it with mosquitto_pub -r -n -t '" + shown + "')");
    return;
  }
  auto parsed = parseFleetCommand(stream, command, payload);
  auto names = streamNames();
  if (parsed && std::find(names.begin(), names.end(), stream) == names.end())
    parsed = unexpected("no stream '" + printableText(stream) + "' here");
  if (!parsed) {
    logLine("MQTT " + printableText(topicName) + ": " + parsed.error() + "; ignored");
    return;
  }
  // To the main loop, where the pipeline is driven.
  auto* handed = new std::pair<FleetPublisher*, FleetCommand>(this, *parsed);
  g_main_context_invoke_full(
      nullptr, G_PRIORITY_HIGH,
      [](gpointer data) {
        auto* job = static_cast<std::pair<FleetPublisher*, FleetCommand>*>(data);
        job->first->apply_(job->second);
        return G_SOURCE_REMOVE;
      },
      handed,
      [](gpointer data) { delete static_cast<std::pair<FleetPublisher*, FleetCommand>*>(data); });
}

void FleetPublisher::announce(const Announcement& announcement) {
  std::string topicName = announcementTopic(announcement.id);
  std::string text = toJson(announcement).dump();
  {
    std::lock_guard lock(retainedMutex_);
    announcementTopic_ = topicName;
    announcement_ = text;
    // Each vehicle's first camera here: the one whose wirccontrol steers it.
    vehicleStreams_.clear();
    for (const auto& camera : announcement.cameras)
      if (camera.vehicle && !camera.vehicle->serial.empty())
        vehicleStreams_.emplace(camera.vehicle->serial, camera.name);
  }
  client_->publish(topicName, text, true, 1);
}

void FleetPublisher::status(const std::string& stream, const nlohmann::json& status, bool force) {
  auto& state = streams_[stream];
  std::string text = status.dump();
  auto now = std::chrono::steady_clock::now();
  if (!force && text == state.lastStatus && now - state.statusAt < kStatusInterval) return;
  state.lastStatus = text;
  state.statusAt = now;
  {
    std::lock_guard lock(retainedMutex_);
    retained_[stream] = text;
  }
  client_->publish(topic(stream, "status"), text, true);
}

void FleetPublisher::detections(const std::string& stream, const nlohmann::json& message,
                                bool anyTags) {
  auto& state = streams_[stream];
  // Frames without tags say nothing, except the first after some had.
  if (!anyTags && !state.hadTags) return;
  auto now = std::chrono::steady_clock::now();
  bool lostThem = !anyTags && state.hadTags;
  if (!lostThem && settings_.detectionsRate > 0 &&
      now - state.detectionsAt < std::chrono::duration<double>(1.0 / settings_.detectionsRate))
    return;
  state.hadTags = anyTags;
  state.detectionsAt = now;
  client_->publish(topic(stream, "detections"), message.dump());
}

void FleetPublisher::event(const std::string& stream, const nlohmann::json& event) {
  client_->publish(topic(stream, "events"), event.dump());
}

void FleetPublisher::snapshot(const std::string& stream, const std::string& jpeg) {
  client_->publish(topic(stream, "snapshot"), jpeg, true);
}

}  // namespace wircam::recorder
