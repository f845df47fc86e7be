#include "status/event_text.h"

namespace wircam::recorder {

std::string eventText(const nlohmann::json& event) {
  std::string type = event.value("type", "event");
  // The link's and the vehicle's own words ("login ok", "link lost: ...").
  if (event.contains("event") && event["event"].is_string()) {
    std::string text = event["event"];
    return type == "vehicle" ? "vehicle: " + text : text;
  }
  if (type == "state") return "state: " + event.value("state", "?");
  if (type == "segment-closed")
    return "segment closed: " + event.value("file", "?") + " (" +
           std::to_string(event.value("frames", 0)) + " frames)";
  // Anything else: its type, then its fields as they are.
  nlohmann::json rest = event;
  rest.erase("type");
  return rest.empty()
             ? type
             : type + " " + rest.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
}

}  // namespace wircam::recorder
