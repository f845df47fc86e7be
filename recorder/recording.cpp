#include "recording.h"

#include <glib-unix.h>
#include <libsoup/soup.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <filesystem>
#include <set>
#include <string_view>

#include "gst_json.h"
#include "log_line.h"
#include "segment_inspector.h"
#include "telemetry_track_flags.h"
#include "wall_clock.h"

namespace wircam::recorder {

namespace {

// A minute of positions at 10 Hz: the trail the live view's map starts with.
constexpr size_t kTrailPositions = 600;

// /api/cameras' state: live, offline or connecting (the device not seen yet).
const char* apiState(const std::string& state) {
  if (state == "live") return "live";
  if (state == "offline") return "offline";
  return "connecting";
}

// --detect FAMILY against the families apriltagdetect knows (its GEnum).
std::optional<std::string> checkFamily(const std::string& family) {
  if (family.empty()) return std::nullopt;
  GstElement* detector = gst_element_factory_make("apriltagdetect", nullptr);
  if (!detector) return "--detect needs apriltagdetect: are the wircam plugins on GST_PLUGIN_PATH?";
  auto* spec =
      G_PARAM_SPEC_ENUM(g_object_class_find_property(G_OBJECT_GET_CLASS(detector), "family"));
  std::string known;
  bool found = false;
  for (guint i = 0; i < spec->enum_class->n_values; ++i) {
    std::string nick = spec->enum_class->values[i].value_nick;
    found |= nick == family;
    known += (known.empty() ? "" : ", ") + nick;
  }
  gst_object_unref(detector);
  if (found) return std::nullopt;
  return "--detect " + family + ": not an AprilTag family (" + known + ")";
}

}  // namespace

Recording::Recording(RecorderOptions options)
    : options_(std::move(options)),
      retention_(options_.outDir, {options_.maxBytes, options_.minFree}, logLine),
      disk_(options_.outDir),
      index_(options_.outDir) {}

Expected<std::unique_ptr<Recording>, std::string> Recording::create(
    const RecorderOptions& options) {
  std::error_code error;
  std::filesystem::create_directories(options.outDir, error);
  if (error) return unexpected("cannot create '" + options.outDir + "': " + error.message());
  if (access(options.outDir.c_str(), W_OK) != 0)
    return unexpected("cannot write into '" + options.outDir + "'");
  if (options.codec == Codec::kH264 &&
      !gst_registry_check_feature_version(gst_registry_get(), "x264enc", 1, 0, 0))
    return unexpected(
        "--codec h264 needs x264enc, from Debian's gstreamer1.0-plugins-ugly "
        "(tools/install-deps installs it)");

  if (auto problem = checkFamily(options.detectFamily)) return unexpected(*problem);

  std::unique_ptr<Recording> recording(new Recording(options));
  // Segments the index lacks (a crash's last one, or a lost index).
  auto inspect = [](const std::filesystem::path& file) {
    markTelemetryTrack(file);  // a file the recorder did not finish
    return inspectSegment(file);
  };
  if (size_t added = recording->index_.reconcile(inspect))
    logLine("indexed " + std::to_string(added) + " segment(s) missing from " +
            recording->index_.path().string());
  recording->index_.save();
  auto plan = planPipeline(options);
  SegmentLimits limits{.maxDuration = static_cast<uint64_t>(options.segmentSeconds * GST_SECOND),
                       .maxBytes = options.segmentBytes};
  for (auto& streamPlan : plan.streams) {
    auto stream = std::make_unique<Stream>();
    stream->plan = streamPlan;
    GError* parseError = nullptr;
    stream->pipeline = gst_parse_launch(streamPlan.description.c_str(), &parseError);
    if (parseError) {
      std::string message = parseError->message;
      g_error_free(parseError);
      if (stream->pipeline) gst_object_unref(stream->pipeline);
      return unexpected("cannot build the pipeline (are the wircam plugins on GST_PLUGIN_PATH?): " +
                        message);
    }
    // Named after its camera, so that the log says whose it is.
    gst_object_set_name(GST_OBJECT(stream->pipeline), streamPlan.name.c_str());
    auto elementNamed = [&](const std::string& name) {
      GstElement* found = gst_bin_get_by_name(GST_BIN(stream->pipeline), name.c_str());
      gst_object_unref(found);  // the pipeline keeps it
      return found;
    };
    stream->stateSinceUnixMs = g_get_real_time() / 1000;
    stream->planner = std::make_unique<SegmentPlanner>(options.outDir, streamPlan.name,
                                                       extensionOf(options.container), limits);
    stream->track.emplace(elementNamed(streamPlan.telemetrySource));
    stream->telemetry = std::make_unique<TelemetryRouter>(*stream->planner, *stream->track);
    stream->splitter = std::make_unique<SegmentSplitter>(
        SegmentSplitter::Parts{.source = elementNamed(streamPlan.source),
                               .splitmux = elementNamed(streamPlan.muxer),
                               .transcoded = plan.transcoded},
        *stream->planner, [telemetry = stream->telemetry.get()] { telemetry->onFrame(); });
    if (!streamPlan.liveSink.empty())
      stream->frames = std::make_unique<FrameTap>(elementNamed(streamPlan.liveSink));
    for (const auto* element : {&streamPlan.source, &streamPlan.muxer, &streamPlan.detector,
                                &streamPlan.controller, &streamPlan.positions})
      if (!element->empty()) recording->streamByElement_[*element] = stream.get();
    recording->streams_.push_back(std::move(stream));
  }
  if (auto problem = recording->startServers()) return unexpected(*problem);
  return recording;
}

std::optional<std::string> Recording::startServers() {
  if (options_.http) {
    HttpServer::Content content;
    for (auto& s : streams_) content.cameras.push_back({s->plan.name, s->frames.get()});
    content.recordingsFolder = options_.outDir;
    content.token = options_.httpToken;
    content.status = [this] { return status(); };
    content.trails = [this] { return trails(); };
    content.cameraStates = [this] {
      nlohmann::json cameras = nlohmann::json::array();
      for (const auto& s : streams_) {
        auto control = controlOf(*s);
        cameras.push_back({{"name", s->plan.name},
                           {"state", apiState(s->state)},
                           {"fps", std::round(s->fps * 10) / 10},
                           {"has_control", control.hasControl},
                           {"following", control.following}});
      }
      return cameras;
    };
    content.deleteRecording = [this](const std::string& file) { return deleteSegment(file); };
    content.recordings = [this] {
      nlohmann::json list = nlohmann::json::array();
      for (const auto& entry : index_.entries()) list.push_back(toJson(entry));
      return list;
    };
    content.openSegments = [this] { return openSegments(); };
    content.command = [this](const FleetCommand& c) { return applyCommand(c, "web"); };
    content.drive = [this](const std::string& camera, double steering, double throttle) {
      return drive(camera, steering, throttle);
    };
    auto server = HttpServer::start(
        *options_.http, std::move(content),
        std::chrono::milliseconds(static_cast<int64_t>(options_.httpIdleSeconds * 1000)));
    if (!server) return server.error();
    http_ = std::move(*server);
    logLine("live view at " + http_->url());
  }
  if (options_.mqtt) {
    FleetPublisher::Settings settings{.url = *parseMqttUrl(*options_.mqtt),
                                      .prefix = options_.mqttPrefix,
                                      .detectionsRate = options_.mqttDetectionsRate};
    for (auto& s : streams_) settings.streams.push_back(s->plan.name);
    auto fleet =
        FleetPublisher::start(settings, [this](const FleetCommand& c) { applyCommand(c, "MQTT"); });
    if (!fleet) return fleet.error();
    fleet_ = std::move(*fleet);
    logLine("MQTT to " + settings.url.host + ":" + std::to_string(settings.url.port) + " under " +
            settings.prefix + "/");
  }
  if (!options_.onSegmentClosed.empty()) {
    hook_ = std::make_unique<SegmentHook>(
        options_.onSegmentClosed,
        std::chrono::seconds(static_cast<int64_t>(options_.hookTimeoutSeconds)),
        [this](const std::string& name, const nlohmann::json& event) {
          if (Stream* s = streamNamed(name)) publishEvent(*s, event);
        });
  }
  if (options_.rtsp) {
    std::vector<RtspServer::Camera> cameras;
    for (auto& s : streams_)
      cameras.push_back(
          {"/" + s->plan.device + "/cam" + std::to_string(s->plan.camera), s->frames.get()});
    auto server = RtspServer::start(*options_.rtsp, cameras);
    if (!server) return server.error();
    rtsp_ = std::move(*server);
    for (auto& camera : cameras) logLine("RTSP at " + rtsp_->url() + camera.path);
  }
  return std::nullopt;
}

Recording::~Recording() {
  // The servers first: they listen to the pipeline's frames.
  http_.reset();
  rtsp_.reset();
  hook_.reset();
  fleet_.reset();  // says offline
  for (auto& stream : streams_) gst_element_set_state(stream->pipeline, GST_STATE_NULL);
  // The splitters and taps hold the elements' pads: before the pipelines go.
  std::vector<GstElement*> pipelines;
  for (auto& stream : streams_) pipelines.push_back(stream->pipeline);
  streams_.clear();
  for (GstElement* pipeline : pipelines) gst_object_unref(pipeline);
  if (loop_) g_main_loop_unref(loop_);
}

Recording::Stream* Recording::streamOf(GstMessage* message) {
  // Elements inside a splitmuxsink (its filesink) are found by their
  // parent; anything else by the camera's pipeline it is in.
  for (GstObject* object = GST_MESSAGE_SRC(message); object; object = GST_OBJECT_PARENT(object)) {
    auto found = streamByElement_.find(GST_OBJECT_NAME(object) ? GST_OBJECT_NAME(object) : "");
    if (found != streamByElement_.end()) return found->second;
    if (Stream* stream = streamOfPipeline(object)) return stream;
  }
  return nullptr;
}

Recording::Stream* Recording::streamOfPipeline(GstObject* pipeline) {
  for (auto& s : streams_)
    if (GST_OBJECT(s->pipeline) == pipeline) return s.get();
  return nullptr;
}

GstClockTime Recording::runningTime(const Stream& stream) const {
  GstClockTime now = GST_CLOCK_TIME_NONE;
  if (GstClock* clock = gst_element_get_clock(stream.pipeline)) {
    now = gst_clock_get_time(clock) - gst_element_get_base_time(stream.pipeline);
    gst_object_unref(clock);
  }
  return now;
}

void Recording::writeTelemetry(Stream& stream, nlohmann::json line, GstClockTime time) {
  if (!GST_CLOCK_TIME_IS_VALID(time)) return;
  stream.telemetry->write(std::move(line), time, unixMsOf(stream.pipeline, time));
  if (auto failure = stream.telemetry->takeWriteFailure()) logLine(*failure);
}

void Recording::onSegmentClosed(Stream& stream, const std::string& file) {
  markTelemetryTrack(file);
  auto planned = stream.planner->segmentOf(file);
  if (!planned) return;
  std::error_code error;
  index_.add({.camera = stream.plan.name,
              .file = std::filesystem::path(file).filename().string(),
              .startUtc = SegmentPlanner::isoUtc(planned->startUnixMs),
              .durationSeconds = planned->durationSeconds(),
              .frames = planned->frames,
              .bytes = std::filesystem::file_size(file, error)});
  auto sidecar = TelemetryLog::pathFor(file);
  publishEvent(stream, {{"type", "segment-closed"},
                        {"file", std::filesystem::path(file).filename().string()},
                        {"path", file},
                        {"sidecar", sidecar},
                        {"start_utc", SegmentPlanner::isoUtc(planned->startUnixMs)},
                        {"duration_s", planned->durationSeconds()},
                        {"frames", planned->frames}});
  if (hook_) hook_->segmentClosed(stream.plan.name, file, sidecar);
  auto open = openSegments();
  updateIndex(retention_.enforce({open.begin(), open.end()}));
}

void Recording::publishEvent(const Stream& stream, const nlohmann::json& event) {
  if (!fleet_) return;
  nlohmann::json line = event;
  line["utc"] = SegmentPlanner::isoUtc(g_get_real_time() / 1000);
  fleet_->event(stream.plan.name, line);
}

GstElement* Recording::element(const std::string& name) const {
  if (name.empty()) return nullptr;
  for (const auto& stream : streams_) {
    GstElement* found = gst_bin_get_by_name(GST_BIN(stream->pipeline), name.c_str());
    if (!found) continue;
    gst_object_unref(found);  // the pipeline keeps it
    return found;
  }
  return nullptr;
}

Recording::Control Recording::controlOf(const Stream& s) const {
  GstElement* controller = element(s.plan.controller);
  if (!controller) return {};
  gboolean hasControl = FALSE, following = FALSE;
  gint target = -1;
  g_object_get(controller, "has-control", &hasControl, "enabled", &following, "target-id", &target,
               nullptr);
  return {.hasControl = hasControl != FALSE, .following = following != FALSE, .target = target};
}

nlohmann::json Recording::positionJson(const Stream& s) const {
  nlohmann::json position = nullptr;
  if (s.position)
    position = {{"beacon", s.position->beacon},
                {"x", s.position->x},
                {"y", s.position->y},
                {"z", s.position->z},
                {"utc", SegmentPlanner::isoUtc(s.position->unixMs)},
                {"stale", !s.positionStale.empty()}};
  else if (!s.positionStale.empty())
    position = {{"stale", true}};  // none came: say why
  if (!s.positionStale.empty()) position["stale_reason"] = s.positionStale;
  return position;
}

std::optional<std::pair<guint, std::string>> Recording::deleteSegment(const std::string& file) {
  using Refusal = std::pair<guint, std::string>;
  for (const auto& path : openSegments())
    if (std::filesystem::path(path).filename() == file)
      return Refusal(SOUP_STATUS_CONFLICT,
                     "'" + file + "' is being recorded; it can go once closed");
  const auto& entries = index_.entries();
  if (std::none_of(entries.begin(), entries.end(), [&](const auto& e) { return e.file == file; }))
    return Refusal(SOUP_STATUS_NOT_FOUND, "no recording named '" + file + "'");
  auto video = std::filesystem::path(options_.outDir) / file;
  if (auto error = removeSegment(video))
    return Refusal(SOUP_STATUS_INTERNAL_SERVER_ERROR,
                   "cannot delete '" + file + "': " + error.message());
  logLine("deleted " + file + " (asked over HTTP)");
  updateIndex({video.string()});
  return std::nullopt;
}

nlohmann::json Recording::fleetStatus(const Stream& s) const {
  double total = static_cast<double>(s.frameCount + s.incomplete);
  auto control = controlOf(s);
  nlohmann::json status = {
      {"state", s.state},
      {"state_since_utc", SegmentPlanner::isoUtc(s.stateSinceUnixMs)},
      {"fps", std::round(s.fps * 10) / 10},
      {"loss",
       total > 0 ? std::round(1000.0 * static_cast<double>(s.incomplete) / total) / 10 : 0.0},
      {"battery_v", s.batteryMv / 1000.0},
      {"has_control", control.hasControl},
      {"following", control.following},
      {"position", positionJson(s)}};
  return status;
}

void Recording::publishFleetStatus(bool force) {
  if (!fleet_) return;
  for (const auto& s : streams_) fleet_->status(s->plan.name, fleetStatus(*s), force);
}

Recording::Stream* Recording::streamNamed(const std::string& name) {
  for (auto& s : streams_)
    if (s->plan.name == name) return s.get();
  return nullptr;
}

std::optional<std::string> Recording::applyCommand(const FleetCommand& command, const char* from) {
  Stream* s = streamNamed(command.stream);
  if (!s) return "no camera named '" + command.stream + "'";
  GstElement* controller = element(s->plan.controller);
  if (!controller) {
    std::string why = command.stream + " does not follow (start with --detect FAMILY --follow)";
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
  publishEvent(*s, event);
  writeTelemetry(*s, event, runningTime(*s));
  publishFleetStatus(true);
  return std::nullopt;
}

std::optional<bool> Recording::drive(const std::string& stream, double steering, double throttle) {
  Stream* s = streamNamed(stream);
  GstElement* controller = s ? element(s->plan.controller) : nullptr;
  if (!controller) return std::nullopt;
  gboolean obeyed = FALSE;
  g_signal_emit_by_name(controller, "drive", steering, throttle, &obeyed);
  return obeyed != FALSE;
}

void Recording::updateIndex(const std::vector<std::string>& deleted) {
  for (const auto& file : deleted) index_.remove(std::filesystem::path(file).filename().string());
  if (!index_.save()) logLine("cannot write " + index_.path().string());
}

void Recording::followLinkState(Stream& stream, const std::string& linkState,
                                const std::string& reason) {
  stream.linkReason = linkState == "live" ? "" : printableText(reason);
  std::string state = stream.state;
  if (linkState == "live") state = "live";
  // Until the first login the device is awaited; afterwards it went away.
  else if (stream.state != "waiting for device")
    state = "offline";
  if (state == stream.state) return;
  stream.state = state;
  stream.stateSinceUnixMs = g_get_real_time() / 1000;
}

void Recording::handleElementMessage(GstMessage* message) {
  const GstStructure* s = gst_message_get_structure(message);
  Stream* stream = streamOf(message);
  if (!s || !stream) return;
  std::string type = gst_structure_get_name(s);
  if (type == "splitmuxsink-fragment-opened") {
    stream->segment = gst_structure_get_string(s, "location");
    stream->telemetry->segmentOpened(stream->segment);
    if (auto failure = stream->telemetry->takeWriteFailure()) logLine(*failure);
    return;
  }
  if (type == "splitmuxsink-fragment-closed") {
    std::string file = gst_structure_get_string(s, "location");
    // (Finalised in the background: the next file may be open already.)
    if (file == stream->segment) stream->segment.clear();
    onSegmentClosed(*stream, file);
    return;
  }

  nlohmann::json line = toJson(s);
  if (type == "wirc-session") {
    // Link events: losses, logins, the control right, refusals. (A loss
    // ends the segment by itself: the planner cuts at the gap in frames.)
    std::string event = gst_structure_get_string(s, "event");
    logLine(stream->plan.name + ": " + printableText(event));
    line["type"] = "session";
    writeTelemetry(*stream, line, runningTime(*stream));
    publishEvent(*stream, line);
    if (const char* state = gst_structure_get_string(s, "state")) {
      const char* reason = gst_structure_get_string(s, "reason");
      followLinkState(*stream, state, reason ? reason : "");
    }
    return;
  }
  if (type == "wirc-stats") {
    guint64 frames = stream->frameCount, bytes = stream->bytes;
    gst_structure_get_uint64(s, "frames-complete", &stream->frameCount);
    gst_structure_get_uint64(s, "frames-incomplete", &stream->incomplete);
    gst_structure_get_uint64(s, "bytes", &stream->bytes);
    gst_structure_get_uint(s, "battery-mv", &stream->batteryMv);
    gboolean stale = FALSE;
    guint64 age = 0;
    gst_structure_get_boolean(s, "status-stale", &stale);
    gst_structure_get_uint64(s, "status-age-ms", &age);
    stream->statusStale = stale;
    stream->statusAgeMs = age;
    // Rates over the time between two reports, whatever their interval.
    GstClockTime now = runningTime(*stream);
    if (GST_CLOCK_TIME_IS_VALID(stream->statsTime) && now > stream->statsTime) {
      double seconds = static_cast<double>(now - stream->statsTime) / GST_SECOND;
      stream->fps = static_cast<double>(stream->frameCount - frames) / seconds;
      stream->kbps = static_cast<double>(stream->bytes - bytes) * 8 / 1000 / seconds;
    }
    stream->statsTime = now;
    line["type"] = "stats";
    writeTelemetry(*stream, line, now);
    return;
  }
  if (type == "wirc-vehicle") {
    // The steered vehicle's own link (RCOIP, BTEMP, or WiRC) and its status
    // reports: battery, RSSI, pins.
    if (const char* state = gst_structure_get_string(s, "state"))
      logLine(stream->plan.name + ": vehicle " +
              printableText(gst_structure_get_string(s, "event")) + " (" + state + ")");
    line["type"] = "vehicle";
    writeTelemetry(*stream, line, runningTime(*stream));
    if (line.contains("state")) publishEvent(*stream, line);  // link changes, not each report
    return;
  }
  if (type == "marvelmind-position" || type == "marvelmind-stale") {
    handlePosition(*stream, s);
    return;
  }
  if (type == "wirc-drive") {
    // Driving by hand from the page: each command, and the dead-man's neutral.
    line["type"] = "drive";
    writeTelemetry(*stream, line, runningTime(*stream));
    return;
  }
  if (type != "apriltag" && type != "wirc-control") return;
  // Detections and commands belong to a frame: its timestamp is their time.
  line["type"] = type == "apriltag" ? "detections" : "control";
  GstClockTime pts = line["timestamp"].get<GstClockTime>();
  line.erase("timestamp");
  if (http_ && type == "apriltag") http_->publishDetections(stream->plan.name, line["detections"]);
  if (fleet_ && type == "apriltag")
    fleet_->detections(stream->plan.name,
                       {{"utc", SegmentPlanner::isoUtc(unixMsOf(stream->pipeline, pts))},
                        {"frame", line.value("frame", 0)},
                        {"tags", line["detections"]}},
                       !line["detections"].empty());
  writeTelemetry(*stream, line, pts);
}

void Recording::handlePosition(Stream& stream, const GstStructure* s) {
  guint beacon = 0;
  gst_structure_get_uint(s, "beacon", &beacon);
  if (gst_structure_has_name(s, "marvelmind-stale")) {
    std::string reason = gst_structure_get_string(s, "reason");
    logLine(stream.plan.name + ": position of beacon " + std::to_string(beacon) +
            " stale: " + reason);
    stream.positionStale = reason;
    nlohmann::json line = {{"type", "position-stale"}, {"beacon", beacon}, {"reason", reason}};
    writeTelemetry(stream, line, runningTime(stream));
    publishEvent(stream, line);
    return;
  }
  Stream::Position position{.beacon = beacon};
  gst_structure_get_double(s, "x", &position.x);
  gst_structure_get_double(s, "y", &position.y);
  gst_structure_get_double(s, "z", &position.z);
  // When it was measured (a position from before PLAYING has no running time).
  guint64 measured = GST_CLOCK_TIME_NONE;
  gst_structure_get_uint64(s, "running-time", &measured);
  GstClockTime time = GST_CLOCK_TIME_IS_VALID(measured) ? measured : runningTime(stream);
  position.unixMs = unixMsOf(stream.pipeline, time);
  stream.position = position;
  stream.positionStale.clear();
  stream.trail.push_back(position);
  if (stream.trail.size() > kTrailPositions) stream.trail.pop_front();
  // Until a frame opens the first file, where the vehicle is belongs to no
  // recording (and must not crowd the session events out of the early lines).
  if (!stream.planner->current()) return;
  writeTelemetry(stream,
                 {{"type", "position"},
                  {"beacon", beacon},
                  {"x", position.x},
                  {"y", position.y},
                  {"z", position.z}},
                 time);
}

void Recording::handleError(GstMessage* message) {
  GError* error = nullptr;
  gchar* debug = nullptr;
  gst_message_parse_error(message, &error, &debug);
  bool diskFull = g_error_matches(error, GST_RESOURCE_ERROR, GST_RESOURCE_ERROR_NO_SPACE_LEFT);
  logLine(std::string(GST_OBJECT_NAME(GST_MESSAGE_SRC(message))) + ": " + error->message + "\n" +
          (debug ? debug : ""));
  g_error_free(error);
  g_free(debug);
  Stream* stream = streamOf(message);
  if (diskFull) {
    // A write failed: the other streams can still be finished.
    exitCode_ = kExitDiskFull;
    if (stream) endStream(*stream);
    if (!stopping_) {
      logLine("the disk is full: finishing the other files; earlier segments are untouched");
      stop(nullptr);
    }
    quitWhenAllEnded();
    return;
  }
  if (exitCode_ == 0) exitCode_ = kExitError;
  if (!stream) {
    g_main_loop_quit(loop_);
    return;
  }
  // One camera's error is its own: the others record on.
  endStream(*stream);
  logLine(stream->plan.name + ": stopped after the error above" +
          (std::all_of(streams_.begin(), streams_.end(), [](const auto& s) { return s->ended; })
               ? ""
               : "; the other cameras record on"));
  quitWhenAllEnded();
}

void Recording::endStream(Stream& stream) {
  if (stream.ended) return;
  stream.ended = true;
  gst_element_set_state(stream.pipeline, GST_STATE_NULL);
  // Its open file was not finished by EOS, but what it holds is playable
  // (streamable Matroska, fragmented MP4): indexed like any other.
  if (!stream.segment.empty()) onSegmentClosed(stream, std::exchange(stream.segment, ""));
}

void Recording::quitWhenAllEnded() {
  if (std::all_of(streams_.begin(), streams_.end(), [](const auto& s) { return s->ended; }))
    g_main_loop_quit(loop_);
}

gboolean Recording::onBusMessage(GstBus*, GstMessage* message, gpointer data) {
  auto* self = static_cast<Recording*>(data);
  switch (GST_MESSAGE_TYPE(message)) {
    case GST_MESSAGE_ELEMENT:
      self->handleElementMessage(message);
      break;
    case GST_MESSAGE_WARNING: {
      GError* error = nullptr;
      gchar* debug = nullptr;
      gst_message_parse_warning(message, &error, &debug);
      logLine(std::string("warning from ") + GST_OBJECT_NAME(GST_MESSAGE_SRC(message)) + ": " +
              error->message + " (" + (debug ? debug : "") + ")");
      g_error_free(error);
      g_free(debug);
      break;
    }
    case GST_MESSAGE_ERROR:
      self->handleError(message);
      break;
    case GST_MESSAGE_EOS:
      // A camera's pipeline finished its files (after the stop's EOS).
      if (Stream* stream = self->streamOfPipeline(GST_MESSAGE_SRC(message))) {
        stream->ended = true;
        stream->segment.clear();
      }
      self->quitWhenAllEnded();
      break;
    default:
      break;
  }
  return TRUE;
}

namespace {
constexpr int kHookDrainSeconds = 15;
}  // namespace

void Recording::stop(const char* why) {
  if (stopping_) return;
  stopping_ = true;
  if (why) logLine(std::string(why) + ": finishing the files (a second signal stops at once)");
  auto hasFrames = [](const auto& s) { return s->planner->current().has_value(); };
  bool anyRecorded = std::any_of(streams_.begin(), streams_.end(), hasFrames);
  if (!anyRecorded) {
    // No device ever sent a frame: nothing to finish (and no EOS in flight
    // while the pipeline is torn down). Stopped by a signal while waiting
    // is how a service ends; a --duration that recorded nothing failed.
    logLine("nothing was recorded: no device sent a frame");
    if (exitCode_ == 0 && !stoppedBySignal_) exitCode_ = kExitError;
    g_main_loop_quit(loop_);
    return;
  }
  // What waited for frames that will not come goes into the last files.
  for (auto& s : streams_) s->telemetry->finish();
  // EOS to each camera that has frames to finish: its splitmuxsink closes
  // its last segment cleanly. A camera that never sent one has nothing to
  // finish (and would never pass EOS on).
  for (auto& s : streams_) {
    if (s->ended) continue;
    if (!hasFrames(s))
      s->ended = true;
    else
      gst_element_send_event(s->pipeline, gst_event_new_eos());
  }
  timers_.push_back(g_timeout_add(kFinishTimeMs, onFinishDeadline, this));
  quitWhenAllEnded();
}

gboolean Recording::onFinishDeadline(gpointer data) {
  auto* self = static_cast<Recording*>(data);
  std::string late;
  for (auto& s : self->streams_) {
    if (s->ended) continue;
    late += (late.empty() ? "" : ", ") + s->plan.name;
    self->endStream(*s);
  }
  if (!late.empty())
    logLine("cut off after " + std::to_string(kFinishTimeMs) + " ms: " + late +
            " (its last file is indexed as it is)");
  g_main_loop_quit(self->loop_);
  return G_SOURCE_REMOVE;
}

gboolean Recording::onStop(gpointer data) {
  auto* self = static_cast<Recording*>(data);
  if (self->stopping_) {
    logLine("stopping now, without finishing the files");
    if (self->exitCode_ == 0) self->exitCode_ = kExitError;
    g_main_loop_quit(self->loop_);
    if (self->hook_) self->hook_->stopDraining();
    return G_SOURCE_CONTINUE;
  }
  self->stoppedBySignal_ = true;
  self->stop("stopping");
  return G_SOURCE_CONTINUE;
}

gboolean Recording::onDurationOver(gpointer data) {
  static_cast<Recording*>(data)->stop("--duration is over");
  return G_SOURCE_REMOVE;
}

gboolean Recording::onHeartbeat(gpointer data) {
  auto* self = static_cast<Recording*>(data);
  // At the newest frame the source has sent, never ahead of the video, and
  // only once the first frame has opened a file.
  for (auto& s : self->streams_)
    if (auto open = s->planner->current()) s->track->heartbeat(open->lastFrame);
  return G_SOURCE_CONTINUE;
}

gboolean Recording::onTick(gpointer data) {
  auto* self = static_cast<Recording*>(data);
  self->printStatus();
  self->guardDisk();
  return G_SOURCE_CONTINUE;
}

void Recording::guardDisk() {
  if (stopping_) return;
  uint64_t rate = 0;
  for (auto& s : streams_) rate += static_cast<uint64_t>(s->kbps * 1000 / 8);
  if (!disk_.nearlyFull(rate)) return;
  // Old segments may make room (--max-bytes/--min-free); if not, stop while
  // the open segments can still be finished.
  auto open = openSegments();
  updateIndex(retention_.enforce({open.begin(), open.end()}));
  if (!disk_.nearlyFull(rate)) return;
  logLine("the disk under " + options_.outDir + " is full (" + std::to_string(disk_.free() >> 20) +
          " MiB free, " + std::to_string(DiskGuard::reserveFor(rate) >> 20) +
          " MiB kept to finish the files); stopping. Free some space or use --max-bytes / "
          "--min-free to delete old segments as you go");
  exitCode_ = kExitDiskFull;
  stop(nullptr);
}

void Recording::printStatus() {
  bool terminal = isatty(STDOUT_FILENO);
  // On a terminal the lines are redrawn in place; in a log, appended.
  if (terminal && statusShown_) std::printf("\033[%zuA", streams_.size());
  auto positionText = [](const Stream& stream) -> std::string {
    if (!stream.position) return "";
    char text[64];
    std::snprintf(text, sizeof text, "  at %.2f, %.2f m%s", stream.position->x, stream.position->y,
                  stream.positionStale.empty() ? "" : " (stale)");
    return text;
  };
  for (auto& s : streams_) {
    if (s->state == "waiting for device") {
      std::printf("%s%-20s waiting for device\n", terminal ? "\033[K" : "", s->plan.name.c_str());
      continue;
    }
    double total = static_cast<double>(s->frameCount + s->incomplete);
    double loss = total > 0 ? 100.0 * static_cast<double>(s->incomplete) / total : 0;
    // A device that stopped reporting keeps its last battery reading, marked.
    std::string stale =
        s->statusStale ? " (stale, " + std::to_string(s->statusAgeMs / 1000) + " s old)" : "";
    std::printf(
        "%s%-20s %7llu frames %5.1f fps  loss %4.1f%%  %7.0f kbit/s  battery %5.2f V%s%s  %s\n",
        terminal ? "\033[K" : "", s->plan.name.c_str(),
        static_cast<unsigned long long>(s->frameCount), s->fps, loss, s->kbps,
        s->batteryMv / 1000.0, stale.c_str(), positionText(*s).c_str(),
        std::filesystem::path(s->segment).filename().c_str());
  }
  std::fflush(stdout);
  statusShown_ = true;
}

nlohmann::json Recording::status() const {
  nlohmann::json streams = nlohmann::json::array();
  for (const auto& s : streams_) {
    double total = static_cast<double>(s->frameCount + s->incomplete);
    nlohmann::json stream = {
        {"name", s->plan.name},
        {"device", s->plan.device},
        {"camera", s->plan.camera},
        {"state", s->state},
        {"state_since_utc", SegmentPlanner::isoUtc(s->stateSinceUnixMs)},
        {"link_reason", s->linkReason},
        {"frames", s->frameCount},
        {"fps", s->fps},
        {"loss_percent", total > 0 ? 100.0 * static_cast<double>(s->incomplete) / total : 0.0},
        {"kbps", s->kbps},
        {"battery_v", s->batteryMv / 1000.0},
        {"status_stale", s->statusStale},
        {"status_age_ms", s->statusAgeMs},
        {"segment", std::filesystem::path(s->segment).filename().string()},
        {"live", "/live/" + s->plan.name + ".mjpg"}};
    if (!s->plan.controller.empty()) {
      auto control = controlOf(*s);
      stream["has_control"] = control.hasControl;
      stream["following"] = control.following;
      stream["target"] = control.target;
    }
    if (!s->plan.positions.empty()) stream["position"] = positionJson(*s);
    if (rtsp_)
      stream["rtsp"] =
          rtsp_->url() + "/" + s->plan.device + "/cam" + std::to_string(s->plan.camera);
    streams.push_back(stream);
  }
  nlohmann::json result = {{"out", options_.outDir},
                           {"free_bytes", disk_.free()},
                           {"stopping", stopping_},
                           {"streams", streams}};
  if (fleet_) {
    auto mqtt = fleet_->stats();
    result["mqtt"] = {{"connected", fleet_->connected()},
                      {"published", mqtt.published},
                      {"dropped", mqtt.dropped},
                      {"connects", mqtt.connects}};
  }
  return result;
}

nlohmann::json Recording::trails() const {
  nlohmann::json trails = nlohmann::json::object();
  for (const auto& s : streams_) {
    if (s->trail.empty()) continue;
    nlohmann::json points = nlohmann::json::array();
    for (const auto& p : s->trail)
      points.push_back({{"x", p.x}, {"y", p.y}, {"utc", SegmentPlanner::isoUtc(p.unixMs)}});
    trails[s->plan.name] = {{"points", points}, {"stale", !s->positionStale.empty()}};
  }
  return trails;
}

std::vector<std::string> Recording::openSegments() const {
  std::vector<std::string> open;
  for (const auto& s : streams_)
    if (!s->segment.empty()) open.push_back(s->segment);
  return open;
}

int Recording::run() {
  loop_ = g_main_loop_new(nullptr, FALSE);
  for (auto& s : streams_) {
    GstBus* bus = gst_element_get_bus(s->pipeline);
    gst_bus_add_watch(bus, onBusMessage, this);
    gst_object_unref(bus);
  }
  g_unix_signal_add(SIGINT, onStop, this);
  g_unix_signal_add(SIGTERM, onStop, this);
  if (options_.duration)
    timers_.push_back(
        g_timeout_add(static_cast<guint>(*options_.duration * 1000), onDurationOver, this));
  timers_.push_back(g_timeout_add(static_cast<guint>(options_.statusSeconds * 1000), onTick, this));
  timers_.push_back(
      g_timeout_add(TelemetryTrack::kHeartbeatInterval / GST_MSECOND, onHeartbeat, this));
  // Once a second, whatever --status says: the fleet's status is published
  // on change and at least every FleetPublisher::kStatusInterval.
  if (fleet_)
    timers_.push_back(g_timeout_add_seconds(
        1,
        [](gpointer self) -> gboolean {
          static_cast<Recording*>(self)->publishFleetStatus();
          return G_SOURCE_CONTINUE;
        },
        this));

  auto removeWatches = [this] {
    for (auto& s : streams_) {
      GstBus* bus = gst_element_get_bus(s->pipeline);
      gst_bus_remove_watch(bus);
      gst_object_unref(bus);
    }
  };
  for (auto& s : streams_) {
    if (gst_element_set_state(s->pipeline, GST_STATE_PLAYING) != GST_STATE_CHANGE_FAILURE) continue;
    // The error itself comes on the bus; show it.
    GstBus* bus = gst_element_get_bus(s->pipeline);
    if (GstMessage* message = gst_bus_pop_filtered(bus, GST_MESSAGE_ERROR)) {
      handleError(message);
      gst_message_unref(message);
    }
    gst_object_unref(bus);
    removeWatches();
    return kExitError;
  }
  g_main_loop_run(loop_);
  // The run is over: its timers must not fire while the hooks drain.
  for (guint id : timers_)
    if (GSource* timer = g_main_context_find_source_by_id(nullptr, id)) g_source_destroy(timer);
  removeWatches();
  for (auto& s : streams_) gst_element_set_state(s->pipeline, GST_STATE_NULL);
  printStatus();
  if (hook_) {
    // The last segments' uploads get a little time; what is left is named.
    for (const auto& left : hook_->drain(std::chrono::seconds(kHookDrainSeconds)))
      logLine("--on-segment-closed did not get to " + left + " before exit");
  }
  return exitCode_;
}

}  // namespace wircam::recorder
