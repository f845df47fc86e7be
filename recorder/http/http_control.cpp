// HttpServer's control of the vehicles: follow, target and control-right
// commands, and who may drive; all behind the access token.
#include <cstdlib>
#include <nlohmann/json.hpp>

#include "common/printable_text.h"
#include "http/camera_feed.h"
#include "http/http_responses.h"
#include "http/http_routes.h"
#include "http/http_server.h"

namespace wircam::recorder {

// Control and deletion are always behind the token: without one set, nobody
// may (the page is then open to anyone who can reach this machine's port).
bool HttpServer::refusedWithoutToken(SoupServerMessage* message, const char* what) {
  if (!content_.token.empty()) return false;
  respondJsonError(message, SOUP_STATUS_FORBIDDEN,
                   std::string(what) + " needs the server started with --http-token");
  return true;
}

Expected<std::pair<std::string, std::string>, std::string> HttpServer::topicCommandOf(
    const std::string& action, GHashTable* query) {
  auto lookup = [&](const char* key) -> std::string {
    const char* value = queryValue(query, key);
    return value ? value : "";
  };
  if (action == "follow") {
    std::string on = lookup("on");
    if (on != "true" && on != "false")
      return unexpected(std::string("follow takes on=true or on=false"));
    return std::pair<std::string, std::string>("follow/set", on == "true" ? "ON" : "OFF");
  }
  if (action == "target") return std::pair<std::string, std::string>("target/set", lookup("id"));
  if (action == "drive") {
    nlohmann::json drive;
    for (const char* key : {"steering", "throttle"}) {
      std::string value = lookup(key);
      char* end = nullptr;
      double read = std::strtod(value.c_str(), &end);
      if (value.empty() || *end != '\0')
        return unexpected(std::string("drive takes steering=S&throttle=T, each -1..1"));
      drive[key] = read;
    }
    return std::pair<std::string, std::string>("drive/set", drive.dump());
  }
  return std::pair<std::string, std::string>("request-control", "");
}

void HttpServer::serveCommand(SoupServerMessage* message, const Route& route, GHashTable* query) {
  if (refusedWithoutToken(message, "controlling the vehicle")) return;
  // The same commands as over MQTT, with their checks.
  auto command = topicCommandOf(route.action, query);
  if (!command) return respondJsonError(message, SOUP_STATUS_BAD_REQUEST, command.error());
  auto parsed = parseFleetCommand(route.name, command->first, command->second);
  if (!parsed) return respondJsonError(message, SOUP_STATUS_BAD_REQUEST, parsed.error());
  if (auto refused = content_.command(*parsed)) {
    bool unknown = std::none_of(feeds_.begin(), feeds_.end(),
                                [&](const auto& feed) { return feed->name == route.name; });
    return respondJsonError(message, unknown ? SOUP_STATUS_NOT_FOUND : SOUP_STATUS_CONFLICT,
                            *refused);
  }
  for (const auto& camera : content_.cameraStates())
    if (camera.value("name", "") == route.name)
      return respond(message, SOUP_STATUS_OK, "application/json", camera.dump());
  respond(message, SOUP_STATUS_OK, "application/json", "{}");
}

void HttpServer::serveReload(SoupServerMessage* message) {
  if (refusedWithoutToken(message, "reloading the config")) return;
  auto changed = content_.reload ? content_.reload()
                                 : unexpected(std::string("this recorder has no config to reload"));
  if (!changed) return respondJsonError(message, SOUP_STATUS_BAD_REQUEST, changed.error());
  respond(message, SOUP_STATUS_OK, "application/json", changed->dump());
}

void HttpServer::refuseDriveUnlessAllowed(SoupServerMessage* message, const std::string& camera) {
  if (refusedWithoutToken(message, "driving")) return;
  if (std::none_of(feeds_.begin(), feeds_.end(),
                   [&](const auto& feed) { return feed->name == camera; }))
    return respondJsonError(message, SOUP_STATUS_NOT_FOUND, "no camera named '" + camera + "'");
  // Allowed but not a WebSocket handshake: libsoup answers 400. Once
  // upgraded it is not idle between a driver's commands: open until either
  // side closes it.
  connections_->upgrading(message);
}

}  // namespace wircam::recorder
