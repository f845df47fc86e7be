// The servers a supervisor starts beside its cameras (web, MQTT, the
// segment hook, RTSP, Foxglove), each fed from the supervisor's own state
// and commands.
#include "app/live_servers_module.h"
#include "app/supervisor.h"
#include "fleet/recorder_id.h"
#include "log_line.h"
#include "record/segment_planner.h"
#include "status/camera_report.h"

namespace wircam::recorder {

namespace {

// A token that would cross the network in clear is said so, with the way out.
void warnIfTokenInClear(const RecorderOptions& options, const ServerAddress& address,
                        const char* plain, const char* secure) {
  std::string host = address.listenHost();
  if (options.httpToken.empty() || !options.httpCert.empty() || host == "127.0.0.1" ||
      host == "localhost" || host == "::1")
    return;
  logLine("the access token travels in clear over " + std::string(plain) + " on " + host +
          ": anyone on the network can read it; give --http-cert and --http-key for " + secure);
}

WebCamera webCameraOf(Camera& c) { return {c.name(), c.frames(), c.encodedFrames()}; }

FoxgloveCamera foxgloveCameraOf(Camera& c) {
  return {c.name(), c.frames(), c.encodedFrames(), !c.plan().positions.empty()};
}

RtspCamera rtspCameraOf(Camera& c) {
  return {"/" + c.plan().device + "/cam" + std::to_string(c.plan().camera), c.frames()};
}

}  // namespace

void Supervisor::addToServers(Camera& camera) {
  if (http_) http_->addCamera(webCameraOf(camera));
  if (foxglove_) foxglove_->addCamera(foxgloveCameraOf(camera));
  if (rtsp_) {
    auto mount = rtspCameraOf(camera);
    rtsp_->addCamera(mount);
    logLine("RTSP at " + rtsp_->url() + mount.path);
  }
  if (fleet_) fleet_->setStreams(cameraNames());
  announce();
}

void Supervisor::removeFromServers(Camera& camera) {
  if (http_) http_->removeCamera(camera.name());
  if (foxglove_) foxglove_->removeCamera(camera.name());
  if (rtsp_) rtsp_->removeCamera(rtspCameraOf(camera).path);
  if (fleet_) fleet_->setStreams(cameraNames());
  announce();
}

std::optional<std::string> Supervisor::startServers() {
  if (options_.http) {
    auto servers = liveServers();
    if (!servers) return servers.error();
    WebContent content;
    for (auto& c : cameras_) content.cameras.push_back(webCameraOf(*c));
    content.recordingsFolder = options_.outDir;
    content.token = options_.httpToken;
    content.certificateFile = options_.httpCert;
    content.keyFile = options_.httpKey;
    content.webrtc = options_.webrtc;
    content.iceServers = {options_.webrtcStun, options_.webrtcTurn};
    content.webrtcKbps = options_.webrtcKbps;
    content.status = [this] { return status(); };
    content.metrics = [this] { return metrics(); };
    content.trails = [this] { return trails(); };
    content.cameraStates = [this] {
      nlohmann::json cameras = nlohmann::json::array();
      for (const auto& c : cameras_) cameras.push_back(withVehicle(cameraJson(c->report()), *c));
      return cameras;
    };
    content.deleteRecording = [this](const std::string& file) { return deleteSegment(file); };
    content.recordings = [this] {
      nlohmann::json list = nlohmann::json::array();
      for (const auto& entry : index_.entries()) list.push_back(toJson(entry));
      return list;
    };
    content.openSegments = [this] { return openSegments(); };
    content.command = [this](const FleetCommand& c) { return commands_.apply(c, "web"); };
    content.reload = [this] { return reload(); };
    if (options_.fleet) {
      content.fleet = [this](const FleetViewScope& scope) {
        return fleet_ && fleet_->directory() ? fleet_->directory()->view(scope) : nlohmann::json();
      };
      content.commandVehicle = [this](const std::string& serial, const std::string& command,
                                      const std::string& payload) -> std::optional<std::string> {
        if (!fleet_ || !fleet_->connected() || !fleet_->commandVehicle(serial, command, payload))
          return "the MQTT broker is not connected: the command cannot reach the vehicle";
        return std::nullopt;
      };
    }
    content.drive = [this](const std::string& camera, double steering, double throttle) {
      return commands_.drive(camera, steering, throttle, "web");
    };
    auto server = (*servers)->startWeb(
        *options_.http, std::move(content),
        std::chrono::milliseconds(static_cast<int64_t>(options_.httpIdleSeconds * 1000)));
    if (!server) return server.error();
    http_ = std::move(*server);
    logLine("live view at " + http_->url());
    warnIfTokenInClear(options_, *options_.http, "plain HTTP", "HTTPS");
  }
  if (options_.mqtt) {
    FleetPublisher::Settings settings{.url = *parseMqttUrl(*options_.mqtt),
                                      .prefix = options_.mqttPrefix,
                                      .detectionsRate = options_.mqttDetectionsRate};
    settings.url.caFile = options_.mqttCaFile;
    if (options_.mqttDiscovery)
      settings.discovery = DiscoveryNames{.discoveryPrefix = *options_.mqttDiscovery,
                                          .topicPrefix = options_.mqttPrefix,
                                          .version = WIRCAM_VERSION};
    for (auto& c : cameras_) settings.streams.push_back(c->name());
    settings.fleet = options_.fleet;
    auto id = recorderId(options_.outDir);
    if (!id) return id.error();
    recorderId_ = *id;
    auto fleet = FleetPublisher::start(
        settings, [this](const FleetCommand& c) { commands_.apply(c, "MQTT"); });
    if (!fleet) return fleet.error();
    fleet_ = std::move(*fleet);
    logLine("MQTT to " + settings.url.host + ":" + std::to_string(settings.url.port) + " under " +
            settings.prefix + "/");
  }
  if (!options_.onSegmentClosed.empty()) {
    hook_ = std::make_unique<SegmentHook>(
        options_.onSegmentClosed,
        std::chrono::seconds(static_cast<int64_t>(options_.hookTimeoutSeconds)),
        [this](const std::string& name, const nlohmann::json& hookEvent) {
          std::string type = hookEvent.value("type", "");
          if (type == "hook-failed" || type == "hook-gave-up") ++recorded_[name].hookFailures;
          if (Camera* c = cameraNamed(name)) event(*c, hookEvent);
        });
  }
  if (options_.foxglove) {
    auto servers = liveServers();
    if (!servers) return servers.error();
    FoxgloveContent content{.token = options_.httpToken,
                            .certificateFile = options_.httpCert,
                            .keyFile = options_.httpKey,
                            .maxClients = options_.foxgloveMaxClients,
                            .version = WIRCAM_VERSION};
    for (auto& c : cameras_) content.cameras.push_back(foxgloveCameraOf(*c));
    content.drive = [this](const std::string& camera, double steering, double throttle) {
      return commands_.drive(camera, steering, throttle, "Foxglove");
    };
    content.drivable = [this](const std::string& camera) {
      Camera* c = cameraNamed(camera);
      return c && c->controller();
    };
    auto server = (*servers)->startFoxglove(
        *options_.foxglove, std::move(content),
        std::chrono::milliseconds(static_cast<int64_t>(options_.httpIdleSeconds * 1000)));
    if (!server) return server.error();
    foxglove_ = std::move(*server);
    logLine("Foxglove WebSocket at " + foxglove_->url());
    warnIfTokenInClear(options_, *options_.foxglove, "ws://", "wss://");
  }
  if (options_.rtsp) {
    auto servers = liveServers();
    if (!servers) return servers.error();
    std::vector<RtspCamera> cameras;
    for (auto& c : cameras_) cameras.push_back(rtspCameraOf(*c));
    auto server = (*servers)->startRtsp(*options_.rtsp, cameras, options_.httpToken);
    if (!server) return server.error();
    rtsp_ = std::move(*server);
    for (auto& camera : cameras) logLine("RTSP at " + rtsp_->url() + camera.path);
  }
  announce();  // with every server's address known
  return std::nullopt;
}

void Supervisor::publishFoxgloveStatus() {
  int64_t now = g_get_real_time() / 1000;
  for (const auto& c : cameras_) {
    nlohmann::json line = fleetStatusJson(c->report());
    line["type"] = "status";
    line["utc"] = SegmentPlanner::isoUtc(now);
    foxglove_->telemetry(c->name(), line, now);
  }
}

void Supervisor::publishFoxglovePoses() {
  if (!foxglove_) return;
  for (const auto& c : cameras_) {
    const auto& trail = c->trail();
    if (trail.empty()) continue;
    const Position& newest = trail.back();
    int64_t& sent = posesSent_[c->name()];
    if (newest.unixMs == sent) continue;
    sent = newest.unixMs;
    foxglove_->pose(c->name(), newest.x, newest.y, newest.z, newest.unixMs);
  }
}

}  // namespace wircam::recorder
