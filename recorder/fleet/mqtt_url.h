// Where the recorder's MQTT broker is: mqtt://[user:pass@]HOST[:PORT].
#pragma once

#include <cstdint>
#include <string>

#include "common/expected.h"

namespace wircam::recorder {

struct MqttUrl {
  std::string host;
  uint16_t port = 1883;
  std::string user, password;  // percent escapes undone ("%40" is "@")
};
Expected<MqttUrl, std::string> parseMqttUrl(const std::string& text);

}  // namespace wircam::recorder
