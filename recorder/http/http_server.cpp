#include "http/http_server.h"

#include <algorithm>
#include <filesystem>
#include <mutex>
#include <set>

#include "common/printable_text.h"
#include "gst_scoped.h"
#include "http/camera_feed.h"
#include "http/cors.h"
#include "http/http_connections.h"
#include "http/http_responses.h"
#include "http/http_routes.h"
#include "http/page_resources.h"
#include "http/request_head_framer.h"
#include "log_line.h"
#include "record/telemetry_log.h"
#include "recording/playback_stream.h"

namespace wircam::recorder {

namespace fs = std::filesystem;

namespace {

// What a 405 adds to its Allow, where the path has more to say.
std::string methodHint(Route::Kind kind) {
  switch (kind) {
    case Route::Kind::RecordingEntry:
      return " (GET /recordings/FILE downloads it)";
    case Route::Kind::Whep:
      return ", with an SDP offer (Content-Type: application/sdp)";
    case Route::Kind::WhepSession:
      return " to end the session (trickle ICE, PATCH, is not taken)";
    default:
      return "";
  }
}

// libsoup refuses some requests before any handler of ours sees them: a path
// that climbs out with an encoded "..", a scheme that is not the
// connection's. It answers a bare 400 with no body; the reason goes with it
// here, in JSON under /api/ as every error of the API.
void explainRefusal(SoupServerMessage* message, gpointer) {
  if (soup_server_message_get_status(message) != SOUP_STATUS_BAD_REQUEST ||
      soup_server_message_get_response_body(message)->length > 0)
    return;
  GUri* uri = soup_server_message_get_uri(message);
  std::string path = uri ? g_uri_get_path(uri) : "";  // as sent: still encoded
  char* decoded = g_uri_unescape_string(path.c_str(), nullptr);
  std::string reason =
      !decoded ? "the path does not decode (an encoded NUL or a bad %-escape)"
      : std::string_view(decoded).find("/..") != std::string_view::npos
          ? "the path climbs out with an encoded '..': not served"
          : "the request is malformed (an https:// URL over plain HTTP, or the other way round)";
  g_free(decoded);
  if (path.starts_with("/api/")) return respondJsonError(message, SOUP_STATUS_BAD_REQUEST, reason);
  respondError(message, SOUP_STATUS_BAD_REQUEST, reason);
}

// Every request: after libsoup has read (and perhaps refused) its headers.
void watchForRefusal(SoupServer*, SoupServerMessage* message, gpointer) {
  g_signal_connect_after(message, "got-headers", G_CALLBACK(explainRefusal), nullptr);
}

}  // namespace

HttpServer::HttpServer(Content content) : content_(std::move(content)) {}

Expected<std::unique_ptr<HttpServer>, std::string> HttpServer::start(
    const ServerAddress& address, Content content, std::chrono::milliseconds idleTimeout) {
  std::unique_ptr<HttpServer> self(new HttpServer(std::move(content)));
  self->server_ = soup_server_new("server-header", "wirc-recorder", nullptr);
  // Drive messages are a few dozen bytes. Deflated, a megabyte of them
  // passed the 4 KB bound on the wire (DriveSocket) and was inflated whole.
  soup_server_remove_websocket_extension(self->server_, SOUP_TYPE_WEBSOCKET_EXTENSION_DEFLATE);
  auto connections =
      HttpConnections::listen(self->server_, address,
                              {.maxOpen = kMaxConnections,
                               .maxPerAddress = kMaxConnectionsPerAddress,
                               .idleTimeout = idleTimeout},
                              {self->content_.certificateFile, self->content_.keyFile}, "--http");
  if (!connections) return unexpected(connections.error());
  self->connections_ = std::move(*connections);
  self->exports_ = std::make_unique<ExportDownloads>(
      self->content_.recordingsFolder,
      [connections = self->connections_.get()](SoupServerMessage* message) {
        return connections->socketOf(message);
      });
  self->fleetRecordings_ = std::make_unique<FleetRecordings>(
      self->content_.fleet ? [fleet = self->content_.fleet] { return fleet({}); }
                           : std::function<nlohmann::json()>(),
      self->content_.token);
  self->url_ = std::string(self->connections_->tls() ? "https://" : "http://") +
               address.listenHost() + ":" + std::to_string(self->connections_->port()) + "/";

  soup_server_add_early_handler(self->server_, nullptr, onHeaders, self.get(), nullptr);
  soup_server_add_handler(self->server_, nullptr, onRequest, self.get(), nullptr);
  // Upgrades only the requests onRequest leaves unanswered (the drive mode's).
  soup_server_add_websocket_handler(self->server_, nullptr, nullptr, nullptr, onWebSocket,
                                    self.get(), nullptr);
  g_signal_connect(self->server_, "request-started", G_CALLBACK(watchForRefusal), nullptr);
  g_signal_connect(self->server_, "request-finished", G_CALLBACK(onRequestEnded), self.get());
  g_signal_connect(self->server_, "request-aborted", G_CALLBACK(onRequestEnded), self.get());
  auto missing = WebRtcService::missingElements();
  if (self->content_.webrtc && !missing.empty()) {
    std::string names;
    for (const auto& name : missing) names += (names.empty() ? "" : ", ") + name;
    self->webrtcOff_ = "WebRTC is off: GStreamer lacks " + names +
                       " (gstreamer1.0-plugins-bad, gstreamer1.0-nice, gstreamer1.0-plugins-good)";
    logLine(self->webrtcOff_ + "; the live view is MJPEG");
  } else if (self->content_.webrtc) {
    WebRtcService::Settings settings;
    settings.servers = self->content_.iceServers;
    // Viewers reach the recorder where its web server listens, and no
    // further: loopback by default; every interface for 0.0.0.0 or ::.
    std::string host = address.listenHost();
    if (host != "0.0.0.0" && host != "::") settings.servers.localAddresses = {host};
    settings.kbps = self->content_.webrtcKbps;
    settings.idleTimeout = idleTimeout;
    HttpServer* server = self.get();
    settings.driveMessage = [server](const std::string& camera,
                                     std::optional<std::string_view> text) {
      return server->driveOverDataChannel(camera, text);
    };
    settings.neutral = [server](const std::string& camera) {
      if (!server->content_.token.empty()) server->content_.drive(camera, 0, 0);
    };
    self->webrtc_ =
        std::make_unique<WebRtcService>(std::vector<WebRtcService::Camera>{}, std::move(settings));
  }
  for (const auto& camera : self->content_.cameras) self->addCamera(camera);
  return self;
}

void HttpServer::addCamera(const WebCamera& camera) {
  auto feed = std::make_unique<CameraFeed>();
  feed->name = camera.name;
  feed->frames = camera.frames;
  CameraFeed* raw = feed.get();
  // Frames come on the streaming thread; clients live on the main loop,
  // where the feed is looked up again by name (a reload may have removed it).
  feed->listener = feed->frames->listen([this, raw](GstSample* sample) {
    // wircsrc puts the frame size (from the JPEG's SOF) in the caps.
    const GstStructure* caps = gst_sample_get_caps(sample)
                                   ? gst_caps_get_structure(gst_sample_get_caps(sample), 0)
                                   : nullptr;
    int width = 0, height = 0;
    if (caps && gst_structure_get_int(caps, "width", &width) &&
        gst_structure_get_int(caps, "height", &height)) {
      raw->width = width;
      raw->height = height;
    }
    GstBuffer* jpeg = gst_sample_get_buffer(sample);
    {
      std::lock_guard lock(raw->latestMutex);
      gst_buffer_replace(&raw->latest, jpeg);
    }
    if (raw->clientCount.load() == 0) return;
    struct Delivery {
      HttpServer* server;
      std::string camera;
      GstBuffer* jpeg;
      std::weak_ptr<bool> alive;
    };
    auto* delivery = new Delivery{this, raw->name, gst_buffer_ref(jpeg), alive_};
    g_main_context_invoke_full(
        nullptr, G_PRIORITY_DEFAULT,
        [](gpointer data) -> gboolean {
          auto* d = static_cast<Delivery*>(data);
          if (!d->alive.expired()) d->server->sendFrame(d->camera, d->jpeg);
          return G_SOURCE_REMOVE;
        },
        delivery,
        [](gpointer data) {
          auto* d = static_cast<Delivery*>(data);
          gst_buffer_unref(d->jpeg);
          delete d;
        });
  });
  feeds_.push_back(std::move(feed));
  if (webrtc_) webrtc_->addCamera({camera.name, camera.frames, camera.encoded});
}

void HttpServer::removeCamera(const std::string& name) {
  auto found =
      std::find_if(feeds_.begin(), feeds_.end(), [&](const auto& f) { return f->name == name; });
  if (found == feeds_.end()) return;
  CameraFeed& feed = **found;
  // The listener is gone once forget() returns: no frame touches the feed after.
  feed.frames->forget(feed.listener);
  gst_buffer_replace(&feed.latest, nullptr);
  endStreams(feed.clients);
  feeds_.erase(found);
  if (webrtc_) webrtc_->removeCamera(name);
}

void HttpServer::endStreams(std::vector<std::unique_ptr<Client>>& clients) {
  for (auto& client : clients) {
    g_signal_handler_disconnect(client->message, client->wroteHandler);
    g_signal_handler_disconnect(client->message, client->finishedHandler);
    soup_message_body_complete(soup_server_message_get_response_body(client->message));
    soup_server_message_unpause(client->message);
  }
  clients.clear();
}

HttpServer::~HttpServer() {
  for (auto& feed : feeds_) {
    feed->frames->forget(feed->listener);
    gst_buffer_replace(&feed->latest, nullptr);
  }
  alive_.reset();
  auto release = [](std::vector<std::unique_ptr<Client>>& clients) {
    for (auto& client : clients) {
      g_signal_handler_disconnect(client->message, client->wroteHandler);
      g_signal_handler_disconnect(client->message, client->finishedHandler);
    }
    clients.clear();
  };
  for (auto& feed : feeds_) release(feed->clients);
  release(eventClients_);
  release(playbackClients_);
  exports_.reset();  // before libsoup frees the messages it answers
  fleetRecordings_.reset();
  webrtc_.reset();        // each viewer with a drive channel sends neutral
  driveSockets_.clear();  // each sends neutral and closes
  if (server_) {
    soup_server_disconnect(server_);
    g_object_unref(server_);
  }
}

void HttpServer::onRequestEnded(SoupServer*, SoupServerMessage* message, gpointer data) {
  static_cast<HttpServer*>(data)->connections_->requestEnded(message);
}

// After the headers, before any body: only GET and HEAD are served, so a
// body (however large it says it is) is refused unread.
void HttpServer::onHeaders(SoupServer*, SoupServerMessage* message, const char* path, GHashTable*,
                           gpointer data) {
  auto* self = static_cast<HttpServer*>(data);
  // Its connection is no longer idle: the request is answered, however long.
  self->connections_->requestStarted(message);
  std::string method = soup_server_message_get_method(message);
  auto* headers = soup_server_message_get_request_headers(message);
  bool hasBody = soup_message_headers_get_content_length(headers) > 0 ||
                 soup_message_headers_get_encoding(headers) == SOUP_ENCODING_CHUNKED;
  bool known = method == "GET" || method == "HEAD" || method == "DELETE" || method == "POST" ||
               method == "OPTIONS";
  if (known && !hasBody) return;
  // The one body taken: a WebRTC offer, its length given and bounded (read
  // by libsoup into memory, so never more than kMaxOfferBytes).
  goffset length = soup_message_headers_get_content_length(headers);
  bool offer = method == "POST" && routeOf(path).kind == Route::Kind::Whep;
  bool sized = soup_message_headers_get_encoding(headers) == SOUP_ENCODING_CONTENT_LENGTH;
  if (offer && sized && length <= static_cast<goffset>(kMaxOfferBytes)) return;
  // libsoup would read the whole body before answering: answer on the
  // socket now, with the reason in JSON as every error of the API, and
  // close it. Nothing of this request was written yet.
  std::string reason = !known   ? "method " + method + " is not served: GET, HEAD, DELETE or POST"
                       : !offer ? std::string("this request takes no body")
                       : !sized ? std::string("the offer needs a Content-Length (no chunked body)")
                                : "the offer is " + std::to_string(length) + " bytes; at most " +
                                      std::to_string(kMaxOfferBytes);
  std::string body = nlohmann::json{{"error", printableText(reason)}}.dump();
  std::string answer = !known
                           ? "HTTP/1.1 405 Method Not Allowed\r\nAllow: GET, HEAD, DELETE, POST\r\n"
                           : "HTTP/1.1 413 Content Too Large\r\n";
  answer += "Content-Type: application/json\r\nContent-Length: " + std::to_string(body.size()) +
            "\r\nConnection: close\r\n\r\n" + body;
  soup_message_body_set_accumulate(soup_server_message_get_request_body(message), FALSE);
  if (GSocket* socket = self->connections_->socketOf(message)) {
    // Over TLS a plain answer would be noise: the connection just closes.
    if (!self->connections_->tls())
      g_socket_send(socket, answer.data(), answer.size(), nullptr, nullptr);
    // Only our side: shutting the reading side with the client's body
    // unread would send a reset, which can destroy the answer before the
    // client reads it. The body is read and dropped (not kept) until the
    // client stops; libsoup then finds the connection closed for writing.
    g_socket_shutdown(socket, FALSE, TRUE, nullptr);
  }
  // (Never a bare 400: that is libsoup's own refusal, which explainRefusal
  // gives its reason.)
  soup_server_message_set_status(
      message, known ? SOUP_STATUS_REQUEST_ENTITY_TOO_LARGE : SOUP_STATUS_METHOD_NOT_ALLOWED,
      nullptr);
}

// 414 when the request line alone is over the bound, 431 otherwise; the
// connection closed (the head's rest is dropped meanwhile).
void HttpServer::answerOverlongHead(SoupServerMessage* message, GHashTable* query) {
  bool line = g_strcmp0(queryValue(query, "part"), "line") == 0;
  soup_message_headers_replace(soup_server_message_get_response_headers(message), "Connection",
                               "close");
  respondJsonError(message, line ? SOUP_STATUS_REQUEST_URI_TOO_LONG : 431,
                   line ? "the request line is over 64 KiB: shorten the URL's query"
                        : "the request's line and header fields are over 64 KiB together: send "
                          "fewer or shorter headers");
}

void HttpServer::onRequest(SoupServer*, SoupServerMessage* message, const char* path,
                           GHashTable* query, gpointer data) {
  auto* self = static_cast<HttpServer*>(data);
  // What stands for a request head over libsoup's bound (request_head_framer.h).
  if (g_strcmp0(path, kOverlongHeadPath) == 0) return answerOverlongHead(message, query);
  auto route = routeOf(path);
  std::string method = soup_server_message_get_method(message);
  if (sharedAcrossOrigins(route.kind) && !self->content_.token.empty()) {
    // Another recorder's page (cors.h): its preflight carries no token.
    if (method == "OPTIONS") return answerPreflight(message);
    allowAnyOrigin(message);
  }
  if (route.kind != Route::Kind::Login && !self->authorised(message)) {
    // Pages get the sign-in form; the API, streams and files a 401 in JSON.
    if (route.kind == Route::Kind::Page)
      return respond(message, SOUP_STATUS_UNAUTHORIZED, "text/html; charset=utf-8",
                     pageFile("login.html"));
    // Basic first: clients that know only it (VLC, OpenCV, Home Assistant)
    // ask for the user name and password, any name and the token.
    auto* headers = soup_server_message_get_response_headers(message);
    soup_message_headers_append(headers, "WWW-Authenticate", "Basic realm=\"wirc-recorder\"");
    soup_message_headers_append(headers, "WWW-Authenticate", "Bearer realm=\"wirc-recorder\"");
    return respondJsonError(message, SOUP_STATUS_UNAUTHORIZED,
                            "needs the access token: Authorization: Bearer T, or sign in at "
                            "/login");
  }
  // (A HEAD allowed is served as its GET: libsoup leaves the body out.)
  if (const char* allowed = allowedMethods(route.kind); allowed && !methodAllowed(allowed, method))
    return respondMethodNotAllowed(
        message, allowed,
        method + " is not served here; this path takes " + allowed + methodHint(route.kind));
  if (route.kind == Route::Kind::Whep || route.kind == Route::Kind::WhepSession)
    return self->serveWhep(message, route);
  if (method == "DELETE" && allowedMethods(route.kind))
    return self->deleteRecording(message, route.name);
  if (route.kind == Route::Kind::CameraCommand) return self->serveCommand(message, route, query);
  if (route.kind == Route::Kind::FleetVehicleCommand)
    return self->serveVehicleCommand(message, route, query);
  if (route.kind == Route::Kind::ConfigReload) return self->serveReload(message);
  switch (route.kind) {
    case Route::Kind::Login:
      return respond(message, SOUP_STATUS_OK, "text/html; charset=utf-8", pageFile("login.html"));
    case Route::Kind::Page:
      return respond(message, SOUP_STATUS_OK, "text/html; charset=utf-8", self->page());
    case Route::Kind::Status:
      return respond(message, SOUP_STATUS_OK, "application/json", self->content_.status().dump());
    case Route::Kind::Events:
      return self->serveEvents(message);
    case Route::Kind::Live:
      return self->serveLive(message, route.name);
    case Route::Kind::RecordingList:
      return self->serveRecordings(message, "");
    case Route::Kind::Recording:
      return self->serveRecordings(message, route.name);
    case Route::Kind::Cameras:
      return respond(message, SOUP_STATUS_OK, "application/json",
                     self->content_.cameraStates().dump());
    case Route::Kind::Snapshot:
      return self->serveSnapshot(message, route.name);
    case Route::Kind::RecordingIndex:
      return self->serveRecordingIndex(message, query);
    case Route::Kind::Playback:
      return self->servePlayback(message, route.name, query);
    case Route::Kind::Export:
      return self->exports_->serve(message, query);
    case Route::Kind::Fleet:
      if (!self->content_.fleet)
        return respondJsonError(message, SOUP_STATUS_NOT_FOUND,
                                "this recorder was not started with --fleet (and --mqtt)");
      return self->serveFleet(message, query);
    case Route::Kind::FleetRecordings:
      return self->fleetRecordings_->serve(message, query);
    case Route::Kind::Metrics:
      if (!self->content_.metrics)
        return respondError(message, SOUP_STATUS_NOT_FOUND, "no metrics");
      return respond(message, SOUP_STATUS_OK, "text/plain; version=0.0.4; charset=utf-8",
                     self->content_.metrics());
    case Route::Kind::Drive:
      // Left unanswered when allowed: libsoup then upgrades it (onWebSocket).
      return self->refuseDriveUnlessAllowed(message, route.name);
    case Route::Kind::RecordingEntry:
    case Route::Kind::CameraCommand:
    case Route::Kind::FleetVehicleCommand:
    case Route::Kind::ConfigReload:
    case Route::Kind::Whep:
    case Route::Kind::WhepSession:
      return;  // answered above
    case Route::Kind::ApiNotFound:
      return respondJsonError(message, SOUP_STATUS_NOT_FOUND,
                              "no such endpoint; /api/status, /api/events, /api/cameras, "
                              "/api/cameras/NAME/snapshot.jpg, /api/cameras/NAME/follow, "
                              "/api/cameras/NAME/target, /api/cameras/NAME/request-control, "
                              "/api/cameras/NAME/drive, /api/cameras/NAME/whep, /api/recordings, "
                              "/api/export, /api/config/reload");
    case Route::Kind::NotFound:
      return respondError(
          message, SOUP_STATUS_NOT_FOUND,
          "not found; try /, /api/status, /api/events, /api/cameras, /api/recordings, "
          "/live/CAMERA.mjpg, /recordings or /metrics");
  }
}

bool HttpServer::authorised(SoupServerMessage* message) const {
  auto* headers = soup_server_message_get_request_headers(message);
  return carriesToken(soup_message_headers_get_one(headers, "Authorization"),
                      soup_message_headers_get_one(headers, "Cookie"), content_.token);
}

std::string HttpServer::page() const {
  nlohmann::json cameras = nlohmann::json::array();
  // Each card starts in its camera's state (live, offline, ...), with the
  // status figures, so the first picture is already right.
  nlohmann::json status = content_.status ? content_.status() : nlohmann::json::object();
  for (const auto& feed : feeds_) {
    nlohmann::json camera = {{"name", feed->name},
                             {"width", feed->width.load()},
                             {"height", feed->height.load()},
                             {"detections", feed->detections}};
    for (const auto& stream : status.value("streams", nlohmann::json::array()))
      if (stream.value("name", "") == feed->name) camera["status"] = stream;
    cameras.push_back(camera);
  }
  nlohmann::json trails = content_.trails ? content_.trails() : nlohmann::json::object();
  std::string state =
      nlohmann::json{{"cameras", cameras}, {"trails", trails}, {"webrtc", webrtc_ != nullptr}}
          .dump();
  // Inside <script>, "</" could end it early.
  for (size_t at = state.find("</"); at != std::string::npos; at = state.find("</", at))
    state.replace(at, 2, "<\\/");
  return liveViewPage(state);
}

void HttpServer::onWebSocket(SoupServer*, SoupServerMessage*, const char* path,
                             SoupWebsocketConnection* connection, gpointer data) {
  auto* self = static_cast<HttpServer*>(data);
  std::string camera = routeOf(path).name;
  auto socket = std::make_unique<DriveSocket>(
      connection,
      [self, camera](double steering, double throttle) {
        return self->content_.drive(camera, steering, throttle);
      },
      [self](DriveSocket* closed) {
        std::erase_if(self->driveSockets_, [&](const auto& s) { return s.get() == closed; });
      });
  self->driveSockets_.push_back(std::move(socket));
}

}  // namespace wircam::recorder
