// wirc-recorder's web server (libsoup): the live view page, each camera as
// MJPEG over HTTP (multipart/x-mixed-replace, the camera's frames as they
// are), detections as server-sent events, the status as JSON, the
// recordings to list, download, replay and delete, and the vehicle's
// control (follow, target, control right, drive mode over a WebSocket).
// Runs on the main loop's context.
#pragma once

#include <libsoup/soup.h>

#include <atomic>
#include <chrono>
#include <functional>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "camera/frame_tap.h"
#include "common/expected.h"
#include "fleet/fleet_command.h"
#include "http/drive_socket.h"
#include "http/export_downloads.h"
#include "http/fleet_recordings.h"
#include "http/http_connections.h"
#include "http/http_routes.h"
#include "live/live_servers.h"
#include "live/server_address.h"
#include "webrtc/webrtc_service.h"

namespace wircam::recorder {

class HttpServer : public WebServer {
 public:
  using Camera = WebCamera;
  using Content = WebContent;

  // Limits that keep hostile clients from holding the recorder's memory or
  // connections: a request body is never read (only GET and HEAD are
  // served), a connection with no request in progress for `idleTimeout`
  // (silent, idle, or still sending its headers) is closed, and at most
  // kMaxConnections are open at once, kMaxConnectionsPerAddress from one
  // client address (the rest are closed at once). Every connection gives
  // its place back however it ends.
  static constexpr size_t kMaxConnections = 128;
  static constexpr size_t kMaxConnectionsPerAddress = 64;
  // Recordings replayed at once (each a small pipeline); more get a 503.
  static constexpr size_t kMaxPlaybacks = 16;
  static Expected<std::unique_ptr<HttpServer>, std::string> start(
      const ServerAddress& address, Content content,
      std::chrono::milliseconds idleTimeout = std::chrono::seconds(10));
  ~HttpServer() override;

  const std::string& url() const override { return url_; }
  size_t openConnections() const override { return connections_->open(); }
  void publishDetections(const std::string& camera, const nlohmann::json& detections) override;
  void addCamera(const WebCamera& camera) override;
  void removeCamera(const std::string& name) override;

 private:
  struct Client;
  struct CameraFeed;
  explicit HttpServer(Content content);

  static void onRequest(SoupServer*, SoupServerMessage* message, const char* path,
                        GHashTable* query, gpointer self);
  static void onWebSocket(SoupServer*, SoupServerMessage* message, const char* path,
                          SoupWebsocketConnection* connection, gpointer self);
  static void onHeaders(SoupServer*, SoupServerMessage* message, const char* path, GHashTable*,
                        gpointer self);
  static void onRequestEnded(SoupServer*, SoupServerMessage* message, gpointer self);
  static void answerOverlongHead(SoupServerMessage* message, GHashTable* query);
  std::string page() const;  // the live view page with the current state
  bool authorised(SoupServerMessage* message) const;
  void serveLive(SoupServerMessage* message, const std::string& camera);
  void serveEvents(SoupServerMessage* message);
  void serveSnapshot(SoupServerMessage* message, const std::string& camera);
  void serveRecordingIndex(SoupServerMessage* message, GHashTable* query);
  void deleteRecording(SoupServerMessage* message, const std::string& name);
  void serveRecordings(SoupServerMessage* message, const std::string& name);
  void servePlayback(SoupServerMessage* message, const std::string& name, GHashTable* query);
  void serveCommand(SoupServerMessage* message, const Route& route, GHashTable* query);
  // A command's query (follow?on=, target?id=, drive?steering=&throttle=,
  // request-control) as the MQTT topic leaf and payload that carry it, or
  // why it is not one (http_control.cpp).
  static Expected<std::pair<std::string, std::string>, std::string> topicCommandOf(
      const std::string& action, GHashTable* query);
  // Answers with the reason when a drive-mode WebSocket may not open;
  // otherwise leaves the request to libsoup's upgrade.
  void refuseDriveUnlessAllowed(SoupServerMessage* message, const std::string& camera);
  // WHEP: a viewer's offer answered (201, the answer and its session's
  // Location), or a session ended.
  void serveWhep(SoupServerMessage* message, const Route& route);
  // The drive data channel's message for `camera`, obeyed as over the
  // WebSocket (refused without the token): the reply.
  std::string driveOverDataChannel(const std::string& camera, std::optional<std::string_view> text);
  bool refusedWithoutToken(SoupServerMessage* message, const char* what);
  // Keeps `message` open as a stream of chunks in `clients`.
  void openStream(SoupServerMessage* message, const char* contentType,
                  std::vector<std::unique_ptr<Client>>& clients);
  void send(std::vector<std::unique_ptr<Client>>& clients, GBytes* chunk);
  // Skipped for a client kMaxFramesInFlight chunks behind.
  void sendTo(Client& client, GBytes* chunk);
  void sendFrame(const std::string& camera, GstBuffer* jpeg);
  void serveReload(SoupServerMessage* message);  // http_control.cpp
  // GET /api/fleet[?recorder=ID][&cameras=false].
  void serveFleet(SoupServerMessage* message, GHashTable* query);
  // POST /api/fleet/vehicles/SERIAL/ACTION (http_fleet.cpp, as serveFleet).
  void serveVehicleCommand(SoupServerMessage* message, const Route& route, GHashTable* query);
  // Ends these streaming responses (their camera removed) and forgets them.
  void endStreams(std::vector<std::unique_ptr<Client>>& clients);

  Content content_;
  SoupServer* server_ = nullptr;
  std::string url_;
  std::vector<std::unique_ptr<CameraFeed>> feeds_;
  std::vector<std::unique_ptr<Client>> eventClients_;
  std::vector<std::unique_ptr<Client>> playbackClients_;  // each with its replay
  std::vector<std::unique_ptr<DriveSocket>> driveSockets_;
  std::unique_ptr<HttpConnections> connections_;
  std::unique_ptr<ExportDownloads> exports_;
  std::unique_ptr<FleetRecordings> fleetRecordings_;
  std::unique_ptr<WebRtcService> webrtc_;                   // with --webrtc on
  std::string webrtcOff_ = "WebRTC is off (--webrtc off)";  // why, when it is
  // Frames queued for the main loop check it: the server may be gone.
  std::shared_ptr<bool> alive_ = std::make_shared<bool>(true);
};

}  // namespace wircam::recorder
