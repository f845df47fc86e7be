#include "app/command_dispatcher.h"

#include "log_line.h"

namespace wircam::recorder {

std::optional<std::string> CommandDispatcher::apply(const FleetCommand& command, const char* from) {
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

std::optional<bool> CommandDispatcher::drive(const std::string& name, double steering,
                                             double throttle) {
  Camera* camera = find_(name);
  GstElement* controller = camera ? camera->controller() : nullptr;
  if (!controller) return std::nullopt;
  gboolean obeyed = FALSE;
  g_signal_emit_by_name(controller, "drive", steering, throttle, &obeyed);
  return obeyed != FALSE;
}

}  // namespace wircam::recorder
