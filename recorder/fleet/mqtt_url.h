// Where the recorder's MQTT broker is: mqtt://[user:pass@]HOST[:PORT], or
// mqtts:// for TLS (port 8883 by default).
#pragma once

#include <cstdint>
#include <string>

#include "common/expected.h"

namespace wircam::recorder {

struct MqttUrl {
  std::string host;
  uint16_t port = 1883;
  std::string user, password;  // percent escapes undone ("%40" is "@")
  bool tls = false;            // mqtts://
  // The CA that signed the broker's certificate (PEM); empty: the
  // system's CAs. mqtts:// only.
  std::string caFile;
};
Expected<MqttUrl, std::string> parseMqttUrl(const std::string& text);

}  // namespace wircam::recorder
