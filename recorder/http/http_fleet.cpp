// HttpServer's fleet endpoints (--fleet): the fleet's view, whole or a
// recorder at a time, and commands for a vehicle wherever it is.
#include <algorithm>
#include <cstring>
#include <nlohmann/json.hpp>

#include "fleet/fleet_announcement.h"
#include "http/http_responses.h"
#include "http/http_server.h"

namespace wircam::recorder {

namespace {

// A serial that names one level of an MQTT topic, and nothing more.
bool fitsOneTopicLevel(const std::string& serial) {
  return !serial.empty() && serial.size() <= 64 &&
         std::all_of(serial.begin(), serial.end(),
                     [](char c) { return c > ' ' && c < 127 && c != '/' && c != '+' && c != '#'; });
}

}  // namespace

void HttpServer::serveFleet(SoupServerMessage* message, GHashTable* query) {
  if (!content_.fleet)
    return respondJsonError(message, SOUP_STATUS_NOT_FOUND,
                            "this recorder was not started with --fleet (and --mqtt)");
  FleetViewScope scope;
  if (const char* recorder = queryValue(query, "recorder")) scope.recorder = recorder;
  if (const char* cameras = queryValue(query, "cameras")) {
    if (g_strcmp0(cameras, "true") != 0 && g_strcmp0(cameras, "false") != 0)
      return respondJsonError(message, SOUP_STATUS_BAD_REQUEST, "cameras takes true or false");
    scope.cameras = g_strcmp0(cameras, "true") == 0;
  }
  if (const char* match = queryValue(query, "match")) {
    if (!*match || std::strlen(match) > 128)
      return respondJsonError(message, SOUP_STATUS_BAD_REQUEST,
                              "match takes 1 to 128 characters of a camera, vehicle or recorder");
    scope.match = match;
  }
  auto view = content_.fleet(scope);
  if (scope.recorder && view.value("recorders", nlohmann::json::array()).empty())
    return respondJsonError(message, SOUP_STATUS_NOT_FOUND,
                            "no recorder " + *scope.recorder + " in the fleet");
  respond(message, SOUP_STATUS_OK, "application/json", view.dump());
}

void HttpServer::serveVehicleCommand(SoupServerMessage* message, const Route& route,
                                     GHashTable* query) {
  if (!content_.commandVehicle)
    return respondJsonError(message, SOUP_STATUS_NOT_FOUND,
                            "this recorder was not started with --fleet (and --mqtt)");
  if (refusedWithoutToken(message, "controlling a vehicle")) return;
  // The payloads the vehicle's topics take, checked here as its recorder
  // would check them (a bad one is refused now, not logged over there).
  auto topicCommand = topicCommandOf(route.action, query);
  if (!topicCommand)
    return respondJsonError(message, SOUP_STATUS_BAD_REQUEST, topicCommand.error());
  const auto& [command, payload] = *topicCommand;
  auto parsed = parseFleetCommand(route.name, command, payload);
  if (!parsed) return respondJsonError(message, SOUP_STATUS_BAD_REQUEST, parsed.error());
  if (!fitsOneTopicLevel(route.name))
    return respondJsonError(message, SOUP_STATUS_BAD_REQUEST,
                            "a vehicle's serial is up to 64 printable characters, without / + #");
  if (auto refused = content_.commandVehicle(route.name, command, payload))
    return respondJsonError(message, SOUP_STATUS_SERVICE_UNAVAILABLE, *refused);
  respond(message, SOUP_STATUS_ACCEPTED, "application/json",
          nlohmann::json{{"vehicle", route.name},
                         {"topic", kVehicleTopicRoot + route.name + "/" + command},
                         {"payload", payload}}
              .dump());
}

}  // namespace wircam::recorder
