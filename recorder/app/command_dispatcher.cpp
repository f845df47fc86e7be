#include "app/command_dispatcher.h"

#include "log_line.h"

namespace wircam::recorder {

std::optional<std::string> CommandDispatcher::apply(const FleetCommand& command, const char* from) {
  if (command.kind == FleetCommand::Kind::kDrive) return driveBy(command, from);
  Camera* camera = find_(command.stream);
  if (!camera) return "no camera named '" + command.stream + "'";
  GstElement* controller = camera->controller();
  if (!controller) {
    std::string why =
        camera->plan().controller.empty()
            ? command.stream + " does not follow (start with --detect FAMILY --follow)"
            : command.stream + "'s pipeline is restarting; try again in a moment";
    logLine(std::string(from) + " command ignored: " + why);
    return why;
  }
  nlohmann::json event = {{"type", "command"}};
  if (command.kind == FleetCommand::Kind::kFollow) {
    // Off stops the vehicle at once (wirccontrol sends neutral).
    g_object_set(controller, "enabled", command.follow ? TRUE : FALSE, nullptr);
    event["follow"] = command.follow ? "ON" : "OFF";
  } else if (command.kind == FleetCommand::Kind::kTarget) {
    g_object_set(controller, "target-id", command.target, nullptr);
    event["target"] = command.target;
  } else {
    // The answer comes as a wirc-control-right message, into telemetry.
    g_signal_emit_by_name(controller, "request-control");
    event["request_control"] = true;
  }
  event["from"] = from;
  logLine(command.stream + ": " + from + " " + event.dump());
  camera->writeTelemetry(event);
  applied_(*camera, event);
  return std::nullopt;
}

std::optional<std::string> CommandDispatcher::driveBy(const FleetCommand& command,
                                                      const char* from) {
  // Not logged a message at a time (a driver sends a dozen a second):
  // wirccontrol posts each command and its dead-man into the telemetry.
  auto obeyed = drive(command.stream, command.steering, command.throttle, from);
  std::optional<std::string> refused;
  if (!obeyed) refused = command.stream + " cannot be driven (no such camera, or no wirccontrol)";
  if (obeyed && !*obeyed)
    refused = command.stream + " did not obey (no control right, or the link is down)";
  // Said once, not for each of a stream of messages.
  if (refused && refused != lastDriveRefusal_)
    logLine(std::string(from) + " drive command ignored: " + *refused);
  lastDriveRefusal_ = refused;
  return refused;
}

std::optional<bool> CommandDispatcher::drive(const std::string& name, double steering,
                                             double throttle, const char* from) {
  Camera* camera = find_(name);
  GstElement* controller = camera ? camera->controller() : nullptr;
  if (!controller) return std::nullopt;
  // Left following, the vehicle would go back to the tag as soon as the
  // driver let go: what the page's drive mode does first.
  auto control = camera->report().control;
  if (control && control->following && (steering != 0 || throttle != 0))
    apply({.kind = FleetCommand::Kind::kFollow, .stream = name, .follow = false}, from);
  gboolean obeyed = FALSE;
  g_signal_emit_by_name(controller, "drive", steering, throttle, &obeyed);
  return obeyed != FALSE;
}

}  // namespace wircam::recorder
