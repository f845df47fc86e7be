#include "fleet/fleet_command.h"

#include <algorithm>
#include <cctype>
#include <cstdlib>

#include "common/printable_text.h"
#include "fleet/drive_command.h"

namespace wircam::recorder {

Expected<FleetCommand, std::string> parseFleetCommand(const std::string& stream,
                                                      const std::string& command,
                                                      const std::string& payload) {
  FleetCommand parsed{.kind = FleetCommand::Kind::kFollow, .stream = stream};
  std::string upper = payload;
  std::transform(upper.begin(), upper.end(), upper.begin(),
                 [](unsigned char c) { return static_cast<char>(std::toupper(c)); });
  if (command == "follow/set") {
    if (upper != "ON" && upper != "OFF")
      return unexpected("follow/set takes ON or OFF, not '" + printableText(payload.substr(0, 40)) +
                        "'");
    parsed.follow = upper == "ON";
    return parsed;
  }
  if (command == "target/set") {
    char* end = nullptr;
    long id = std::strtol(payload.c_str(), &end, 10);
    // wirccontrol's target-id: what it cannot take must not be answered
    // as taken.
    if (payload.empty() || *end != '\0' || id < -1 || id > 65535)
      return unexpected("a target is a tag id 0..65535 (or -1: the largest), not '" +
                        printableText(payload.substr(0, 40)) + "'");
    parsed.kind = FleetCommand::Kind::kTarget;
    parsed.target = static_cast<int>(id);
    return parsed;
  }
  if (command == "request-control") {
    parsed.kind = FleetCommand::Kind::kRequestControl;
    return parsed;
  }
  if (command == "drive/set") {
    auto drive = parseDriveCommand(payload);
    if (!drive) return unexpected("drive/set: " + drive.error());
    parsed.kind = FleetCommand::Kind::kDrive;
    parsed.steering = drive->steering;
    parsed.throttle = drive->throttle;
    return parsed;
  }
  return unexpected("unknown command '" + printableText(command) +
                    "' (follow/set, target/set, request-control, drive/set)");
}

}  // namespace wircam::recorder
