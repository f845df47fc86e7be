// What wirc-recorder sees of its web, RTSP and Foxglove servers. They live in
// a module of their own (wirc-recorder-servers.so), which the recorder loads
// only for --http, --rtsp or --foxglove (app/live_servers_module.h): their
// code and the libraries
// they bring (libsoup with krb5, sqlite, nghttp2 and psl; the RTSP server;
// WebRTC), about 3 MB resident, stay out of a recorder that serves nothing.
// The recorder links none of it: it starts the servers through the module's
// table and uses them through these interfaces.
#pragma once

#include <glib.h>

#include <chrono>
#include <cstddef>
#include <functional>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "camera/frame_tap.h"
#include "common/expected.h"
#include "fleet/fleet_command.h"
#include "fleet/fleet_directory.h"
#include "live/ice_servers.h"
#include "live/server_address.h"

namespace wircam::recorder {

struct WebCamera {
  std::string name;
  FrameTap* frames;             // borrowed; outlives the server
  FrameTap* encoded = nullptr;  // the recording's H.264 (--codec h264), or null
};

// The HTTP statuses the supervisor answers with (deleteRecording), as
// libsoup numbers them; the recorder itself does not include libsoup.
inline constexpr guint kHttpNotFound = 404, kHttpConflict = 409, kHttpInternalError = 500;

// What the web server shows and obeys, from the supervisor.
struct WebContent {
  std::vector<WebCamera> cameras;
  std::string recordingsFolder;
  std::function<nlohmann::json()> status;  // called on the main thread
  // GET /metrics: the Prometheus text (main thread).
  std::function<std::string()> metrics;
  // /api/cameras: [{name, state, fps, has_control, following}, ...]
  std::function<nlohmann::json()> cameraStates;
  // /api/recordings: the recording index's entries (url added here)
  std::function<nlohmann::json()> recordings;
  std::string token;  // empty: no authentication (this machine only)
  // HTTPS with this certificate and key (PEM files); empty: plain HTTP.
  std::string certificateFile, keyFile;
  // Deletes a finished segment (video and sidecar) and its index entry;
  // the HTTP status and reason when it cannot.
  std::function<std::optional<std::pair<guint, std::string>>(const std::string& file)>
      deleteRecording;
  // Each stream's recent Marvelmind positions, for the page's map:
  // {"<stream>": {"points": [{"x","y","utc"}, ...], "stale": bool}}.
  std::function<nlohmann::json()> trails;
  std::function<std::vector<std::string>()> openSegments;
  // Follow, target, request-control from the page: why not, if refused.
  std::function<std::optional<std::string>(const FleetCommand&)> command;
  // Drive mode: whether the camera's vehicle obeys (nullopt: no control).
  std::function<std::optional<bool>(const std::string& camera, double steering, double throttle)>
      drive;
  // POST /api/config/reload: what changed ({added, removed, restarted,
  // unchanged}), or why nothing did.
  std::function<Expected<nlohmann::json, std::string>()> reload;
  // With --fleet: GET /api/fleet's {"recorders": [...]} (fleet/fleet_directory.h),
  // the whole of which GET /api/fleet/recordings asks; null without.
  std::function<nlohmann::json(const FleetViewScope&)> fleet;
  // With --fleet: a command for a vehicle wherever it is, handed to the
  // broker (fleet_publisher.h: `command` as "follow/set", a checked
  // payload); why not, if it cannot be.
  std::function<std::optional<std::string>(const std::string& serial, const std::string& command,
                                           const std::string& payload)>
      commandVehicle;
  // The WebRTC live view (WHEP at /api/cameras/NAME/whep), with these ICE
  // servers and each camera's VP8 rate.
  bool webrtc = false;
  IceServers iceServers;
  unsigned webrtcKbps = 600;
};

class WebServer {
 public:
  virtual ~WebServer() = default;
  // "http://HOST:PORT/", with the port the system picked for port 0.
  virtual const std::string& url() const = 0;
  // Connections open now (counted from accept to close).
  virtual size_t openConnections() const = 0;
  // Sends one camera's detections to every open page (main thread).
  virtual void publishDetections(const std::string& camera, const nlohmann::json& detections) = 0;
  // A camera a reload added, or removed (its viewers' streams end).
  virtual void addCamera(const WebCamera& camera) = 0;
  virtual void removeCamera(const std::string& name) = 0;
};

struct RtspCamera {
  std::string path;  // "/<device>/cam<N>"
  FrameTap* frames;  // borrowed; outlives the server
};

class RtspService {
 public:
  virtual ~RtspService() = default;
  // "rtsp://HOST:PORT", the port the system picked for port 0.
  virtual const std::string& url() const = 0;
  // A camera a reload added, or removed (its clients' streams end).
  virtual void addCamera(const RtspCamera& camera) = 0;
  virtual void removeCamera(const std::string& path) = 0;
};

struct FoxgloveCamera {
  std::string name;
  FrameTap* frames;             // borrowed; outlives the server
  FrameTap* encoded = nullptr;  // the recording's H.264: then the image channel's
  bool positions = false;       // with Marvelmind: a pose channel
};

// What the Foxglove WebSocket serves and obeys, from the supervisor.
struct FoxgloveContent {
  std::vector<FoxgloveCamera> cameras;
  std::string token;                     // as for the web server
  std::string certificateFile, keyFile;  // TLS, as for the web server
  size_t maxClients = 8;
  std::string version;  // in serverInfo's name
  // Drive mode: whether the camera's vehicle obeys (nullopt: no control).
  std::function<std::optional<bool>(const std::string& camera, double steering, double throttle)>
      drive;
  // Whether the camera steers a vehicle (--follow), for a drive channel.
  std::function<bool(const std::string& camera)> drivable;
};

// The Foxglove WebSocket server (foxglove.websocket.v1): each camera's
// channels (foxglove/foxglove_channels.h) to Foxglove and Lichtblick, and
// /STREAM/drive from them. Main thread only.
class FoxgloveService {
 public:
  struct Stats {
    size_t clients = 0;
    uint64_t refused = 0;  // over the client limit
    uint64_t sent = 0;     // messages
    uint64_t dropped = 0;  // messages a slow client had no room for
  };
  virtual ~FoxgloveService() = default;
  // "ws://HOST:PORT/" (wss:// with TLS), the port the system picked for 0.
  virtual const std::string& url() const = 0;
  virtual Stats stats() const = 0;
  // Channels advertised to every client, and taken back.
  virtual void addCamera(const FoxgloveCamera& camera) = 0;
  virtual void removeCamera(const std::string& name) = 0;
  // The camera's status each second (/STREAM/telemetry), a detections line
  // (/STREAM/tags), an event (/STREAM/log), a position (/STREAM/pose).
  virtual void telemetry(const std::string& camera, const nlohmann::json& line, int64_t unixMs) = 0;
  // A frame's detections are stamped as the frame's image (`framePts`, its
  // PTS): Foxglove draws annotations on the image of their timestamp.
  virtual void detections(const std::string& camera, const nlohmann::json& line, int64_t unixMs,
                          uint64_t framePts) = 0;
  virtual void log(const std::string& camera, const std::string& message, int64_t unixMs) = 0;
  virtual void pose(const std::string& camera, double x, double y, double z, int64_t unixMs) = 0;
};

// The module's table, which its one exported function (kLiveServersEntry)
// returns.
struct LiveServers {
  Expected<std::unique_ptr<WebServer>, std::string> (*startWeb)(
      const ServerAddress& address, WebContent content, std::chrono::milliseconds idleTimeout);
  // With a token every request needs it.
  Expected<std::unique_ptr<RtspService>, std::string> (*startRtsp)(const ServerAddress& address,
                                                                   std::vector<RtspCamera> cameras,
                                                                   const std::string& token);
  Expected<std::unique_ptr<FoxgloveService>, std::string> (*startFoxglove)(
      const ServerAddress& address, FoxgloveContent content, std::chrono::milliseconds idleTimeout);
  // Whether a thread of the module is still at work that exit's handlers
  // would break (WebRTC's DTLS certificate, its RSA key still being made).
  bool (*busyAtExit)();
};

inline constexpr const char* kLiveServersEntry = "wircam_live_servers";

}  // namespace wircam::recorder
