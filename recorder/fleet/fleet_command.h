// The commands the recorder takes over MQTT (and from its web page):
// PREFIX/STREAM/follow/set (ON, OFF), PREFIX/STREAM/target/set (a tag id,
// -1 = the largest), PREFIX/STREAM/request-control (asks the vehicle for
// the control right; any payload) and PREFIX/STREAM/drive/set (driving by
// hand: the drive channels' {"steering": …, "throttle": …}, held for
// wirccontrol's drive-timeout, so a stream of them drives and silence
// stops the vehicle).
#pragma once

#include <string>

#include "common/expected.h"

namespace wircam::recorder {

struct FleetCommand {
  enum class Kind { kFollow, kTarget, kRequestControl, kDrive } kind;
  std::string stream;
  bool follow = false;                // kFollow
  int target = -1;                    // kTarget
  double steering = 0, throttle = 0;  // kDrive, -1..1
};

// A command's topic (after the prefix and stream) and payload, or why it
// is refused.
Expected<FleetCommand, std::string> parseFleetCommand(const std::string& stream,
                                                      const std::string& command,
                                                      const std::string& payload);

}  // namespace wircam::recorder
