#include "http/http_routes.h"

#include <glib.h>

#include <string>

namespace wircam::recorder {

namespace {

constexpr std::string_view kLive = "/live/";
constexpr std::string_view kMjpeg = ".mjpg";
constexpr std::string_view kRecordings = "/recordings/";
constexpr std::string_view kCameras = "/api/cameras/";
constexpr std::string_view kSnapshot = "/snapshot.jpg";

}  // namespace

Route routeOf(std::string_view path) {
  using Kind = Route::Kind;
  if (path == "/" || path == "/index.html") return {Kind::Page, ""};
  if (path == "/login") return {Kind::Login, ""};
  if (path == "/api/status") return {Kind::Status, ""};
  if (path == "/api/events") return {Kind::Events, ""};
  if (path == "/api/cameras") return {Kind::Cameras, ""};
  if (path == "/api/recordings") return {Kind::RecordingIndex, ""};
  if (path == "/api/export") return {Kind::Export, ""};
  if (path == "/api/config/reload") return {Kind::ConfigReload, ""};
  if (path == "/metrics") return {Kind::Metrics, ""};
  if (path == "/api/fleet") return {Kind::Fleet, ""};
  if (path == "/api/fleet/recordings") return {Kind::FleetRecordings, ""};
  constexpr std::string_view kVehicles = "/api/fleet/vehicles/";
  if (path.starts_with(kVehicles)) {
    auto rest = path.substr(kVehicles.size());
    auto slash = rest.find('/');
    if (slash != std::string_view::npos && slash > 0) {
      auto action = rest.substr(slash + 1);
      if (action == "follow" || action == "target" || action == "drive")
        return {Kind::FleetVehicleCommand, std::string(rest.substr(0, slash)), std::string(action)};
    }
  }
  constexpr std::string_view kRecordingEntry = "/api/recordings/";
  if (path.starts_with(kRecordingEntry) && path.size() > kRecordingEntry.size())
    return {Kind::RecordingEntry, std::string(path.substr(kRecordingEntry.size()))};
  if (path.starts_with(kCameras)) {
    // NAME/ACTION, NAME without a slash
    auto rest = path.substr(kCameras.size());
    auto slash = rest.find('/');
    if (slash != std::string_view::npos && slash > 0) {
      std::string camera(rest.substr(0, slash));
      auto action = rest.substr(slash + 1);
      if (action == kSnapshot.substr(1)) return {Kind::Snapshot, camera};
      if (action == "drive") return {Kind::Drive, camera};
      if (action == "whep") return {Kind::Whep, camera};
      constexpr std::string_view kSession = "whep/";
      if (action.starts_with(kSession) && action.size() > kSession.size() &&
          action.find('/', kSession.size()) == std::string_view::npos)
        return {Kind::WhepSession, camera, std::string(action.substr(kSession.size()))};
      if (action == "follow" || action == "target" || action == "request-control")
        return {Kind::CameraCommand, camera, std::string(action)};
    }
  }
  constexpr std::string_view kPlay = "/play/";
  if (path.starts_with(kPlay) && path.ends_with(kMjpeg) &&
      path.size() > kPlay.size() + kMjpeg.size())
    return {Kind::Playback,
            std::string(path.substr(kPlay.size(), path.size() - kPlay.size() - kMjpeg.size()))};
  if (path.starts_with("/api/")) return {Kind::ApiNotFound, ""};
  if (path.starts_with(kLive) && path.ends_with(kMjpeg) &&
      path.size() > kLive.size() + kMjpeg.size())
    return {Kind::Live,
            std::string(path.substr(kLive.size(), path.size() - kLive.size() - kMjpeg.size()))};
  if (path == "/recordings" || path == kRecordings) return {Kind::RecordingList, ""};
  if (path.starts_with(kRecordings))
    return {Kind::Recording, std::string(path.substr(kRecordings.size()))};
  return {Kind::NotFound, ""};
}

const char* allowedMethods(Route::Kind kind) {
  using Kind = Route::Kind;
  switch (kind) {
    case Kind::Recording:
      return "GET, HEAD, DELETE";
    case Kind::RecordingEntry:
    case Kind::WhepSession:
      return "DELETE";
    case Kind::CameraCommand:
    case Kind::FleetVehicleCommand:
    case Kind::Whep:
    case Kind::ConfigReload:
      return "POST";
    // HEAD where a client asks for headers alone: a monitor checking the
    // server is up, a download manager or <video> learning a file's size.
    case Kind::Page:
    case Kind::Login:
    case Kind::Status:
    case Kind::Metrics:
    case Kind::RecordingList:
      return "GET, HEAD";
    // Streams, snapshots and exports: a HEAD would do the work for nothing.
    case Kind::Events:
    case Kind::Live:
    case Kind::Cameras:
    case Kind::Snapshot:
    case Kind::RecordingIndex:
    case Kind::Drive:
    case Kind::Playback:
    case Kind::Export:
    case Kind::Fleet:
    case Kind::FleetRecordings:
      return "GET";
    case Kind::ApiNotFound:
    case Kind::NotFound:
      return nullptr;
  }
  return nullptr;
}

bool methodAllowed(const char* allowed, std::string_view method) {
  if (!allowed || method.empty()) return false;
  std::string_view list = allowed;
  while (!list.empty()) {
    auto comma = list.find(',');
    if (list.substr(0, comma) == method) return true;
    if (comma == std::string_view::npos) break;
    list.remove_prefix(comma + 1);
    while (!list.empty() && list.front() == ' ') list.remove_prefix(1);
  }
  return false;
}

namespace {

bool sameSecret(std::string_view given, std::string_view token) {
  // Every byte is looked at whatever differs, so timing says nothing.
  unsigned char difference = given.size() == token.size() ? 0 : 1;
  for (size_t i = 0; i < given.size(); ++i)
    difference |= static_cast<unsigned char>(given[i] ^ token[i % token.size()]);
  return difference == 0;
}

}  // namespace

// "Basic base64(user:password)" with the token as the password, whatever
// the user name: what VLC, OpenCV and Home Assistant send from a URL's
// user:password@.
bool basicCarries(std::string_view credentials, std::string_view token) {
  std::string encoded(credentials);
  gsize size = 0;
  guchar* decoded = g_base64_decode(encoded.c_str(), &size);
  std::string pair(reinterpret_cast<const char*>(decoded), size);
  g_free(decoded);
  auto colon = pair.find(':');
  return colon != std::string::npos && sameSecret(std::string_view(pair).substr(colon + 1), token);
}

bool carriesToken(const char* authorization, const char* cookie, std::string_view token) {
  if (token.empty()) return true;
  constexpr std::string_view kBearer = "Bearer ", kBasic = "Basic ";
  std::string_view given = authorization ? authorization : "";
  // A scheme's name is case-insensitive (RFC 9110 11.1).
  auto scheme = [&](std::string_view name) {
    return given.size() >= name.size() &&
           g_ascii_strncasecmp(given.data(), name.data(), name.size()) == 0;
  };
  if (scheme(kBearer) && sameSecret(given.substr(kBearer.size()), token)) return true;
  if (scheme(kBasic) && basicCarries(given.substr(kBasic.size()), token)) return true;
  if (!cookie) return false;
  // "a=1; wircam_token=T; b=2"
  std::string_view cookies = cookie;
  while (!cookies.empty()) {
    auto end = cookies.find(';');
    auto pair = cookies.substr(0, end);
    while (!pair.empty() && pair.front() == ' ') pair.remove_prefix(1);
    constexpr std::string_view kName = "wircam_token=";
    if (pair.starts_with(kName) && sameSecret(pair.substr(kName.size()), token)) return true;
    if (end == std::string_view::npos) break;
    cookies.remove_prefix(end + 1);
  }
  return false;
}

const char* recordingContentType(std::string_view name) {
  if (name.ends_with(".mkv")) return "video/x-matroska";
  if (name.ends_with(".mp4")) return "video/mp4";
  if (name.ends_with(".jsonl")) return "application/x-ndjson";
  return nullptr;
}

bool isRecordingName(std::string_view name) {
  return !name.empty() && name.front() != '.' && name.find('/') == std::string_view::npos &&
         name.find('\0') == std::string_view::npos && recordingContentType(name) != nullptr;
}

}  // namespace wircam::recorder
