#include "app/supervisor.h"

#include <glib-unix.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <utility>

#include "app/pipeline_planner.h"
#include "gst_scoped.h"
#include "log_line.h"
#include "record/segment_inspector.h"
#include "record/segment_planner.h"
#include "status/camera_report.h"
#include "status/event_text.h"
#include "telemetry/telemetry_track_flags.h"

namespace wircam::recorder {

namespace {

// A stop's own bound, past the cameras' CameraMachine::kFinishTime: whatever a camera or
// device does, the run ends within 3 s of it.
constexpr std::chrono::milliseconds kStopBound{2900};

}  // namespace

// Its GEnum's values.
std::optional<std::string> Supervisor::checkFamily(const std::string& family) {
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

CameraFiles Supervisor::filesOf(const RecorderOptions& options, const PipelinePlan& plan) {
  return {.folder = options.outDir,
          .extension = extensionOf(options.container),
          .limits = {.maxDuration = static_cast<uint64_t>(options.segmentSeconds * GST_SECOND),
                     .maxBytes = options.segmentBytes},
          .transcoded = plan.transcoded};
}

CameraHealth::Policy Supervisor::healthOf(const RecorderOptions& options) {
  return {.stallTimeout =
              std::chrono::milliseconds(static_cast<int64_t>(options.stallSeconds * 1000))};
}

RetentionLimits Supervisor::retentionOf(const RecorderOptions& options) {
  return {.maxBytes = options.maxBytes,
          .minFree = options.minFree,
          .maxAge = options.maxAge,
          .keepEvents = options.keepEvents};
}

Supervisor::Supervisor(RecorderOptions options, Reread reread)
    : options_(std::move(options)),
      reread_(std::move(reread)),
      retention_(options_.outDir, retentionOf(options_), logLine),
      disk_(options_.outDir),
      index_(options_.outDir),
      commands_([this](const std::string& name) { return cameraNamed(name); },
                [this](Camera& camera, const nlohmann::json& applied) {
                  event(camera, applied);
                  publishFleetStatus(true);
                }),
      vehicles_([this](const std::string&) {
        announce();
        publishFleetStatus(true);
      }) {}

Expected<std::unique_ptr<Supervisor>, std::string> Supervisor::create(
    const RecorderOptions& options, Reread reread) {
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

  std::unique_ptr<Supervisor> supervisor(new Supervisor(options, std::move(reread)));
  // Segments the index lacks (a crash's last one, or a lost index).
  auto inspect = [](const std::filesystem::path& file) {
    markTelemetryTrack(file);  // a file the recorder did not finish
    return inspectSegment(file);
  };
  if (size_t added = supervisor->index_.reconcile(inspect))
    logLine("indexed " + std::to_string(added) + " segment(s) missing from " +
            supervisor->index_.path().string());
  supervisor->index_.save();
  if (auto problem = cameraRecordedTwice(options)) return unexpected(*problem);
  auto plan = planPipeline(options);
  if (auto problem = sameNamedStreams(plan)) return unexpected(*problem);
  for (auto& stream : plan.streams) {
    auto camera = Camera::create(stream, filesOf(options, plan), healthOf(options), *supervisor);
    if (!camera) return unexpected(camera.error());
    supervisor->cameras_.push_back(std::move(*camera));
  }
  if (auto problem = supervisor->startServers()) return unexpected(*problem);
  return supervisor;
}

Supervisor::~Supervisor() {
  // The servers first: they listen to the cameras' frames.
  http_.reset();
  rtsp_.reset();
  foxglove_.reset();  // each client's vehicle sent neutral
  hook_.reset();
  fleet_.reset();  // says offline
  cameras_.clear();
  if (indexSave_) saveIndexNow();  // (its idle source must not outlive this)
  if (loop_) g_main_loop_unref(loop_);
}

Camera* Supervisor::cameraNamed(const std::string& name) {
  for (auto& c : cameras_)
    if (c->name() == name && !removing_.count(c.get())) return c.get();
  return nullptr;
}

std::vector<std::string> Supervisor::cameraNames() const {
  std::vector<std::string> names;
  for (const auto& c : cameras_)
    if (!removing_.count(c.get())) names.push_back(c->name());
  return names;
}

void Supervisor::segmentClosed(Camera& camera, const std::string& file,
                               const PlannedSegment& planned) {
  markTelemetryTrack(file);
  ++segmentsThisRun_;
  std::error_code error;
  auto name = std::filesystem::path(file).filename().string();
  uint64_t bytes = std::filesystem::file_size(file, error);
  if (error) bytes = 0;
  index_.add({.camera = camera.name(),
              .file = name,
              .startUtc = SegmentPlanner::isoUtc(planned.startUnixMs),
              .durationSeconds = planned.durationSeconds(),
              .frames = planned.frames,
              .bytes = bytes,
              .vehicle = toJson(vehicles_.of(camera.plan().device))});
  auto& totals = recorded_[camera.name()];
  ++totals.segmentsClosed;
  totals.frames += planned.frames;
  totals.bytes += bytes;
  auto sidecar = TelemetryLog::pathFor(file);
  event(camera, {{"type", "segment-closed"},
                 {"file", name},
                 {"path", file},
                 {"sidecar", sidecar},
                 {"start_utc", SegmentPlanner::isoUtc(planned.startUnixMs)},
                 {"duration_s", planned.durationSeconds()},
                 {"frames", planned.frames}});
  if (hook_) hook_->segmentClosed(camera.name(), file, sidecar);
  enforceRetention();
}

void Supervisor::publishSnapshots() {
  for (auto& c : cameras_) {
    GstBuffer* jpeg = c->frames() ? c->frames()->latest() : nullptr;
    if (!jpeg) continue;
    if (gst::ScopedBufferMap map(jpeg, GST_MAP_READ); map)
      fleet_->snapshot(c->name(), std::string(map.view()));
    gst_buffer_unref(jpeg);
  }
}

void Supervisor::enforceRetention() {
  // (Without a retention nothing is deleted: gathering every camera's open
  // files at each closed segment is skipped, work that grows with the
  // cameras squared at a stop of hundreds.)
  if (!retention_.active()) return saveIndexSoon();
  auto open = openSegments();
  updateIndex(retention_.enforce({open.begin(), open.end()}));
}

void Supervisor::event(Camera& camera, const nlohmann::json& event) {
  if (event.value("type", "") == "state" && event.value("state", "") == "live") identify(camera);
  if (foxglove_) foxglove_->log(camera.name(), eventText(event), g_get_real_time() / 1000);
  if (!fleet_) return;
  nlohmann::json line = event;
  line["utc"] = SegmentPlanner::isoUtc(g_get_real_time() / 1000);
  fleet_->event(camera.name(), line);
}

void Supervisor::detections(Camera& camera, const nlohmann::json& line, int64_t unixMs,
                            GstClockTime framePts) {
  if (http_) http_->publishDetections(camera.name(), line["detections"]);
  if (foxglove_) foxglove_->detections(camera.name(), line, unixMs, framePts);
  if (fleet_)
    fleet_->detections(camera.name(),
                       {{"utc", SegmentPlanner::isoUtc(unixMs)},
                        {"frame", line.value("frame", 0)},
                        {"tags", line["detections"]}},
                       !line["detections"].empty());
}

void Supervisor::diskFull(Camera&) {
  // A write failed: the other cameras can still finish their files.
  exitCode_ = kExitDiskFull;
  if (!stopping_)
    logLine("the disk is full: finishing the other files; earlier segments are untouched");
  stop(nullptr);
}

void Supervisor::ended(Camera& camera) {
  if (removing_.count(&camera))  // not from inside its own call
    g_idle_add(
        [](gpointer self) -> gboolean {
          static_cast<Supervisor*>(self)->forgetEndedCameras();
          return G_SOURCE_REMOVE;
        },
        this);
  quitWhenAllEnded();
}

void Supervisor::quitWhenAllEnded() {
  if (stopping_ &&
      std::all_of(cameras_.begin(), cameras_.end(), [](const auto& c) { return c->ended(); }))
    g_main_loop_quit(loop_);
}

void Supervisor::stop(const char* why) {
  if (stopping_) return;
  stopping_ = true;
  if (why) logLine(std::string(why) + ": finishing the files (a second signal stops at once)");
  // This run's: a folder of earlier recordings is no excuse (cameras a
  // reload removed are gone from cameras_; their files counted).
  bool anyRecorded =
      segmentsThisRun_ > 0 ||
      std::any_of(cameras_.begin(), cameras_.end(), [](const auto& c) { return c->hasFrames(); });
  if (!anyRecorded && exitCode_ == 0) {
    // No device ever sent a frame. Stopped by a signal while waiting is how
    // a service ends; a --duration that recorded nothing failed.
    logLine("nothing was recorded: no device sent a frame");
    if (!stoppedBySignal_) exitCode_ = kExitError;
  }
  if (schedule_) {
    schedule_->stopping(RunSchedule::Clock::now(), kStopBound);
    armSchedule();
  }
  for (auto& c : cameras_) c->stop();
  quitWhenAllEnded();
}

gboolean Supervisor::onSignal(gpointer data) {
  auto* self = static_cast<Supervisor*>(data);
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

// The one timer of the run's schedule: at its next job.
void Supervisor::armSchedule() {
  if (scheduleTimer_) g_source_remove(scheduleTimer_);
  auto wait =
      std::chrono::ceil<std::chrono::milliseconds>(schedule_->next() - RunSchedule::Clock::now());
  scheduleTimer_ = g_timeout_add(static_cast<guint>(std::clamp<int64_t>(wait.count(), 0, 3600000)),
                                 onSchedule, this);
}

gboolean Supervisor::onSchedule(gpointer data) {
  auto* self = static_cast<Supervisor*>(data);
  self->scheduleTimer_ = 0;
  for (RunJob job : self->schedule_->due(RunSchedule::Clock::now())) self->perform(job);
  self->armSchedule();
  return G_SOURCE_REMOVE;
}

void Supervisor::perform(RunJob job) {
  switch (job) {
    case RunJob::End:
      stop("--duration is over");
      break;
    case RunJob::Status:
      printStatus();
      guardDisk();
      break;
    case RunJob::CameraTick:
      for (auto& c : cameras_) c->tick();
      publishFoxglovePoses();
      break;
    case RunJob::FleetStatus:
      publishFleetStatus();
      break;
    case RunJob::FoxgloveStatus:
      publishFoxgloveStatus();
      break;
    case RunJob::Snapshots:
      publishSnapshots();
      break;
    case RunJob::Retention:
      enforceRetention();
      break;
    case RunJob::StopBackstop:
      // Cameras cut themselves off at CameraMachine::kFinishTime; this is the backstop.
      g_main_loop_quit(loop_);
      break;
  }
}

void Supervisor::publishFleetStatus(bool force) {
  if (!fleet_) return;
  for (const auto& c : cameras_)
    if (!removing_.count(c.get()))  // its retained status was cleared as it went
      fleet_->status(c->name(), withVehicle(fleetStatusJson(c->report()), *c), force);
  if (g_get_monotonic_time() / 1000 - announcedAt_ >= kAnnounceIntervalMs) announce();
}

std::optional<std::pair<guint, std::string>> Supervisor::deleteSegment(const std::string& file) {
  using Refusal = std::pair<guint, std::string>;
  for (const auto& path : openSegments())
    if (std::filesystem::path(path).filename() == file)
      return Refusal(kHttpConflict, "'" + file + "' is being recorded; it can go once closed");
  const auto& entries = index_.entries();
  if (std::none_of(entries.begin(), entries.end(), [&](const auto& e) { return e.file == file; }))
    return Refusal(kHttpNotFound, "no recording named '" + file + "'");
  auto video = std::filesystem::path(options_.outDir) / file;
  if (auto error = removeSegment(video))
    return Refusal(kHttpInternalError, "cannot delete '" + file + "': " + error.message());
  logLine("deleted " + file + " (asked over HTTP)");
  updateIndex({video.string()});
  return std::nullopt;
}

void Supervisor::updateIndex(const std::vector<std::string>& deleted) {
  for (const auto& file : deleted) index_.remove(std::filesystem::path(file).filename().string());
  if (deleted.empty()) return saveIndexSoon();
  saveIndexNow();
}

void Supervisor::saveIndexSoon() {
  if (!indexSave_) indexSave_ = g_idle_add(onSaveIndex, this);
}

gboolean Supervisor::onSaveIndex(gpointer self) {
  auto* supervisor = static_cast<Supervisor*>(self);
  supervisor->indexSave_ = 0;
  supervisor->saveIndexNow();
  return G_SOURCE_REMOVE;
}

void Supervisor::saveIndexNow() {
  if (indexSave_) g_source_remove(std::exchange(indexSave_, 0));
  if (!index_.save()) logLine("cannot write " + index_.path().string());
}

void Supervisor::guardDisk() {
  if (stopping_) return;
  uint64_t rate = 0;
  for (auto& c : cameras_) rate += static_cast<uint64_t>(c->kbps() * 1000 / 8);
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

void Supervisor::printStatus() {
  bool terminal = isatty(STDOUT_FILENO);
  // On a terminal the lines are redrawn in place; in a log, appended.
  if (terminal && statusShown_) std::printf("\033[%zuA", cameras_.size());
  for (auto& c : cameras_)
    std::printf("%s%s\n", terminal ? "\033[K" : "", statusLine(c->report()).c_str());
  std::fflush(stdout);
  statusShown_ = true;
}

std::string Supervisor::rtspOf(const Camera& camera) const {
  if (!rtsp_) return "";
  return rtsp_->url() + "/" + camera.plan().device + "/cam" + std::to_string(camera.plan().camera);
}

nlohmann::json Supervisor::status() const {
  nlohmann::json streams = nlohmann::json::array();
  for (const auto& c : cameras_)
    streams.push_back(withVehicle(statusJson(c->report(), rtspOf(*c)), *c));
  nlohmann::json result = {{"out", options_.outDir},
                           {"free_bytes", disk_.free()},
                           {"stopping", stopping_},
                           {"retention",
                            {{"max_bytes", options_.maxBytes},
                             {"min_free", options_.minFree},
                             {"max_age_s", options_.maxAge.count()},
                             {"keep_events_s", options_.keepEvents.count()}}},
                           {"streams", streams}};
  if (foxglove_) {
    auto served = foxglove_->stats();
    result["foxglove"] = {{"url", foxglove_->url()},
                          {"clients", served.clients},
                          {"max_clients", options_.foxgloveMaxClients},
                          {"refused", served.refused},
                          {"sent", served.sent},
                          {"dropped", served.dropped}};
  }
  if (fleet_) {
    auto mqtt = fleet_->stats();
    result["mqtt"] = {{"connected", fleet_->connected()},
                      {"published", mqtt.published},
                      {"dropped", mqtt.dropped},
                      {"connects", mqtt.connects}};
  }
  return result;
}

std::string Supervisor::metrics() const {
  RecorderMetrics m;
  m.version = WIRCAM_VERSION;
  for (const auto& c : cameras_) m.cameras.push_back(c->report());
  m.recorded = recorded_;
  m.diskFreeBytes = disk_.free();
  m.httpConnections = http_ ? http_->openConnections() : 0;
  if (foxglove_) {
    auto served = foxglove_->stats();
    m.foxglove = RecorderMetrics::Foxglove{.clients = served.clients,
                                           .refused = served.refused,
                                           .sent = served.sent,
                                           .dropped = served.dropped};
  }
  if (fleet_) {
    auto mqtt = fleet_->stats();
    m.mqttConnected = fleet_->connected();
    m.mqttPublished = mqtt.published;
    m.mqttDropped = mqtt.dropped;
  }
  return prometheusText(m);
}

nlohmann::json Supervisor::trails() const {
  nlohmann::json trails = nlohmann::json::object();
  for (const auto& c : cameras_)
    if (!c->trail().empty()) trails[c->name()] = trailJson(c->trail(), c->positionStale());
  return trails;
}

std::vector<std::string> Supervisor::openSegments() const {
  // Not only the files being written: the one before a cut is still being
  // finished (its muxer's end, then its title) until its camera hears so.
  std::vector<std::string> open;
  for (const auto& c : cameras_)
    for (auto& file : c->unfinishedSegments()) open.push_back(std::move(file));
  return open;
}

int Supervisor::run() {
  loop_ = g_main_loop_new(nullptr, FALSE);
  g_unix_signal_add(SIGINT, onSignal, this);
  g_unix_signal_add(SIGTERM, onSignal, this);
  using std::chrono::milliseconds;
  // (--status takes any positive number: past 30 years is never.)
  auto ms = [](double seconds) {
    return milliseconds(std::llround(std::min(seconds, 1e9) * 1000));
  };
  RunPeriods periods{.status = ms(options_.statusSeconds),
                     .cameraTick = milliseconds(Camera::kTickIntervalMs)};
  if (options_.duration) periods.duration = ms(*options_.duration);
  // MQTT's status is published on change and at least every
  // FleetPublisher::kStatusInterval: looked at once a second.
  if (fleet_) periods.fleetStatus = milliseconds(1000);
  if (foxglove_) periods.foxgloveStatus = milliseconds(1000);
  if (fleet_ && options_.mqttDiscovery) periods.snapshots = ms(options_.mqttSnapshotSeconds);
  // Segments age whether or not any camera closes one: --max-age is looked
  // at now and every minute (a reload may set it).
  if (options_.maxAge.count() > 0) enforceRetention();
  schedule_.emplace(periods, RunSchedule::Clock::now());
  armSchedule();
  if (reread_) timers_.push_back(g_unix_signal_add(SIGHUP, onReloadSignal, this));
  for (auto& c : cameras_)
    if (!c->start()) return kExitError;
  g_main_loop_run(loop_);
  // The run is over: its timers must not fire while the hooks drain.
  if (scheduleTimer_) g_source_remove(scheduleTimer_);
  scheduleTimer_ = 0;
  for (guint id : timers_)
    if (GSource* timer = g_main_context_find_source_by_id(nullptr, id)) g_source_destroy(timer);
  printStatus();
  for (auto& c : cameras_) c->halt();  // what still runs (a second signal, the backstop)
  saveIndexNow();                      // with what the cameras' ends closed
  if (hook_) {
    // The last segments' uploads get a little time; what is left is named.
    auto limit = std::chrono::duration<double>(options_.hookDrainSeconds);
    for (const auto& left :
         hook_->drain(std::chrono::duration_cast<std::chrono::milliseconds>(limit)))
      logLine("--on-segment-closed did not get to " + left + " before exit");
  }
  return exitCode_;
}

}  // namespace wircam::recorder
