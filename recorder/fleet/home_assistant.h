// Home Assistant's MQTT discovery for the recorder's cameras: each camera
// one device with a camera entity (its snapshots), a switch for following,
// a number for the target tag, sensors for battery, frame rate and loss, and
// a connectivity binary sensor, all fed by the recorder's own topics
// (PREFIX/STREAM/status, /follow/set, /target/set, /snapshot) and available
// with PREFIX/available. Pure: the topics and payloads, for FleetPublisher
// to publish retained.
#pragma once

#include <string>
#include <utility>
#include <vector>

namespace wircam::recorder {

struct DiscoveryNames {
  std::string discoveryPrefix;  // "homeassistant"
  std::string topicPrefix;      // the recorder's --mqtt-prefix
  std::string version;          // the device block's sw_version
};

using RetainedMessage = std::pair<std::string, std::string>;  // topic, payload

// "PREFIX/+/NODE/+/config": every config this recorder (its topic prefix)
// may have published, to find those of cameras it no longer has.
std::string discoverySubscription(const DiscoveryNames& names);

// A stream's configs, retained.
std::vector<RetainedMessage> discoveryConfigs(const DiscoveryNames& names,
                                              const std::string& stream);

// Whether a config topic is this recorder's (its node id) for a camera it
// no longer has: one to clear with an empty retained message.
bool isStaleConfig(const DiscoveryNames& names, const std::string& topic,
                   const std::vector<std::string>& streams);

// [a-zA-Z0-9_-] only, as discovery topics and unique ids want.
std::string discoveryId(const std::string& text);

}  // namespace wircam::recorder
