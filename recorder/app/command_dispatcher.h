// The one place a command reaches a camera's wirccontrol, whether it came
// over MQTT or from the web page: follow on/off, the target tag, a request
// for the control right, and driving by hand.
#pragma once

#include <functional>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>

#include "camera/camera.h"
#include "fleet/fleet_command.h"

namespace wircam::recorder {

class CommandDispatcher {
 public:
  using FindCamera = std::function<Camera*(const std::string& name)>;
  // After a command was carried out: its event, for MQTT and the status.
  using Applied = std::function<void(Camera& camera, const nlohmann::json& event)>;

  CommandDispatcher(FindCamera find, Applied applied)
      : find_(std::move(find)), applied_(std::move(applied)) {}

  // Why it cannot be carried out (no such camera, it does not follow, it is
  // restarting), if so. `from` names the source in the log: "MQTT", "web".
  std::optional<std::string> apply(const FleetCommand& command, const char* from);
  // Drive mode: following turned off first (left on, the vehicle would go
  // back to the tag as soon as the driver let go); whether the vehicle
  // obeys, or nullopt when the camera has no wirccontrol (or none running).
  std::optional<bool> drive(const std::string& camera, double steering, double throttle,
                            const char* from);

 private:
  // A drive/set command, through drive(); why it was not obeyed, if so.
  std::optional<std::string> driveBy(const FleetCommand& command, const char* from);
  FindCamera find_;
  Applied applied_;
  std::optional<std::string> lastDriveRefusal_;  // logged; until a command is obeyed
};

}  // namespace wircam::recorder
