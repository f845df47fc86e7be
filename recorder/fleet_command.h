// The commands the recorder takes over MQTT: PREFIX/STREAM/follow/set (ON,
// OFF) and PREFIX/STREAM/target/set (a tag id, -1 = the largest).
#pragma once

#include <string>

#include "common/expected.h"

namespace wircam::recorder {

struct FleetCommand {
  enum class Kind { kFollow, kTarget } kind;
  std::string stream;
  bool follow = false;  // kFollow
  int target = -1;      // kTarget
};

// A command's topic (after the prefix and stream) and payload, or why it
// is refused.
Expected<FleetCommand, std::string> parseFleetCommand(const std::string& stream,
                                                      const std::string& command,
                                                      const std::string& payload);

}  // namespace wircam::recorder
