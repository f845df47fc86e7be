#include "fleet/home_assistant.h"

#include <cctype>
#include <nlohmann/json.hpp>

namespace wircam::recorder {

namespace {

std::string nodeId(const DiscoveryNames& names) {
  return "wircam_" + discoveryId(names.topicPrefix);
}

struct Entity {
  const char* component;
  const char* key;  // the object id's end and the unique id's
  nlohmann::json fields;
};

}  // namespace

std::string discoveryId(const std::string& text) {
  std::string id;
  for (char c : text)
    id += std::isalnum(static_cast<unsigned char>(c)) || c == '-' || c == '_' ? c : '_';
  return id;
}

std::string discoverySubscription(const DiscoveryNames& names) {
  return names.discoveryPrefix + "/+/" + nodeId(names) + "/+/config";
}

std::vector<RetainedMessage> discoveryConfigs(const DiscoveryNames& names,
                                              const std::string& stream) {
  std::string base = names.topicPrefix + "/" + stream + "/";
  std::string status = base + "status";
  std::string id = discoveryId(stream);
  nlohmann::json device = {{"identifiers", {"wircam_" + id}},
                           {"name", stream},
                           {"manufacturer", "wircam"},
                           {"model", "WiRC vehicle camera"},
                           {"sw_version", names.version}};
  const Entity entities[] = {
      {"camera", "camera", {{"name", "Camera"}, {"topic", base + "snapshot"}}},
      {"switch",
       "following",
       {{"name", "Following"},
        {"icon", "mdi:target"},
        {"command_topic", base + "follow/set"},
        {"state_topic", status},
        {"value_template", "{{ 'ON' if value_json.following else 'OFF' }}"},
        {"payload_on", "ON"},
        {"payload_off", "OFF"}}},
      {"number",
       "target",
       {{"name", "Target tag"},
        {"icon", "mdi:tag"},
        {"command_topic", base + "target/set"},
        {"state_topic", status},
        {"value_template", "{{ value_json.target }}"},
        {"min", -1},
        {"max", 4095},
        {"step", 1},
        {"mode", "box"}}},
      {"sensor",
       "battery",
       {{"name", "Battery"},
        {"device_class", "voltage"},
        {"unit_of_measurement", "V"},
        {"state_class", "measurement"},
        {"state_topic", status},
        {"value_template", "{{ value_json.battery_v }}"}}},
      {"sensor",
       "fps",
       {{"name", "Frame rate"},
        {"icon", "mdi:filmstrip"},
        {"unit_of_measurement", "fps"},
        {"state_class", "measurement"},
        {"state_topic", status},
        {"value_template", "{{ value_json.fps }}"}}},
      {"sensor",
       "loss",
       {{"name", "Frame loss"},
        {"icon", "mdi:video-off"},
        {"unit_of_measurement", "%"},
        {"state_class", "measurement"},
        {"state_topic", status},
        {"value_template", "{{ value_json.loss }}"}}},
      {"binary_sensor",
       "connectivity",
       {{"name", "Live"},
        {"device_class", "connectivity"},
        {"state_topic", status},
        {"value_template", "{{ 'ON' if value_json.state == 'live' else 'OFF' }}"}}},
  };
  std::vector<RetainedMessage> configs;
  for (const auto& entity : entities) {
    nlohmann::json config = entity.fields;
    config["unique_id"] = "wircam_" + id + "_" + entity.key;
    config["object_id"] = id + "_" + entity.key;
    config["availability_topic"] = names.topicPrefix + "/available";
    config["device"] = device;
    configs.emplace_back(names.discoveryPrefix + "/" + entity.component + "/" + nodeId(names) +
                             "/" + id + "_" + entity.key + "/config",
                         config.dump());
  }
  return configs;
}

bool isStaleConfig(const DiscoveryNames& names, const std::string& topic,
                   const std::vector<std::string>& streams) {
  std::string node = "/" + nodeId(names) + "/";
  auto at = topic.find(node);
  if (!topic.starts_with(names.discoveryPrefix + "/") || at == std::string::npos ||
      !topic.ends_with("/config"))
    return false;
  std::string object = topic.substr(at + node.size());
  for (const auto& stream : streams)
    if (object.starts_with(discoveryId(stream) + "_")) return false;
  return true;
}

}  // namespace wircam::recorder
