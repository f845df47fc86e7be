// What a camera's elements say on its bus, turned into its report, its
// telemetry (sidecar and text track) and its events. (Camera's lifecycle is
// in camera.cpp.)
#include <tuple>

#include "camera/camera.h"
#include "camera/gst_json.h"
#include "camera/wall_clock.h"
#include "log_line.h"
#include "record/segment_planner.h"

namespace wircam::recorder {

namespace {
// A minute of positions at 10 Hz: the trail the live view's map starts with.
constexpr size_t kTrailPositions = 600;
}  // namespace

void Camera::writeTelemetry(nlohmann::json line, GstClockTime time) {
  if (!pipeline_ || !GST_CLOCK_TIME_IS_VALID(time)) return;
  if (machine_.betweenRuns()) {
    // Between a fault and the next run: for the next run's first file.
    carriedTelemetry_.push_back({std::move(line), 0, unixMsOf(pipeline_->pipeline(), time)});
    return;
  }
  auto& telemetry = pipeline_->telemetry();
  telemetry.write(std::move(line), time, unixMsOf(pipeline_->pipeline(), time));
  if (auto failure = telemetry.takeWriteFailure()) logLine(*failure);
}

void Camera::writeTelemetry(const nlohmann::json& line) {
  if (pipeline_) writeTelemetry(line, pipeline_->runningTime());
}

std::optional<bus::Stats> Camera::sourceStatsNow() const {
  GstElement* source = pipeline_ ? pipeline_->element(plan_.source) : nullptr;
  if (!source || !g_object_class_find_property(G_OBJECT_GET_CLASS(source), "stats"))
    return std::nullopt;
  GstStructure* now = nullptr;
  g_object_get(source, "stats", &now, nullptr);
  if (!now) return std::nullopt;
  auto stats = bus::Stats::read(now);
  gst_structure_free(now);
  return stats;
}

void Camera::countFrom(const bus::Stats& stats, CameraReport& report) const {
  report.frames = std::max(report.frames, earlierRuns_.frames + stats.framesComplete);
  report.incomplete = std::max(report.incomplete, earlierRuns_.incomplete + stats.framesIncomplete);
  report.bytes = std::max(report.bytes, earlierRuns_.bytes + stats.bytes);
}

CameraReport Camera::report() const {
  CameraReport report = report_;
  report.everLive = everLive_;
  // The counters as they are now, from the source's own stats (updated at
  // each frame), not as its once-a-second message left them: two scrapes
  // a few seconds apart read the camera's true rate.
  if (auto stats = sourceStatsNow()) countFrom(*stats, report);
  if (!plan_.controller.empty()) {
    ControlReport control;
    if (GstElement* element = controller()) {
      gboolean hasControl = FALSE, following = FALSE;
      g_object_get(element, "has-control", &hasControl, "enabled", &following, "target-id",
                   &control.target, nullptr);
      control.hasControl = hasControl != FALSE;
      control.following = following != FALSE;
    } else if (carriedControl_) {
      // Between runs: what the user set, which the next run takes up (not
      // "not following" for every reconnect's few seconds).
      std::tie(control.following, control.target) = *carriedControl_;
    }
    report.control = control;
  }
  return report;
}

void Camera::handleSession(const GstStructure* s, nlohmann::json line) {
  // Link events: losses, logins, the control right, refusals.
  auto session = bus::Session::read(s);
  logLine(name() + ": " + printableText(session.event));
  line["type"] = "session";
  writeTelemetry(line, pipeline_->runningTime());
  observer_.event(*this, line);
  if (!session.state) return;
  bool live = *session.state == "live";
  report_.linkReason = live ? "" : printableText(session.reason);
  if (live) {
    everLive_ = true;
    apply(machine_.linkUp(CameraHealth::Clock::now()));
  } else if (everLive_) {
    // Lost with a file open: the machine ends the file at its last frame.
    apply(machine_.linkLost(*session.state == "lost" && pipeline_->hasFrames(),
                            CameraHealth::Clock::now()));
  }
}

void Camera::handleStats(const GstStructure* s, nlohmann::json line) {
  auto stats = bus::Stats::read(s);
  uint64_t frames = report_.frames, bytes = report_.bytes;
  // A new pipeline's source counts from 0: its counts add to the camera's.
  runCounts_ = {stats.framesComplete, stats.framesIncomplete, stats.bytes, stats.commandsSent};
  report_.frames = earlierRuns_.frames + runCounts_.frames;
  report_.incomplete = earlierRuns_.incomplete + runCounts_.incomplete;
  report_.bytes = earlierRuns_.bytes + runCounts_.bytes;
  report_.commandsSent = earlierRuns_.commandsSent + runCounts_.commandsSent;
  report_.batteryMv = stats.batteryMv;
  report_.statusStale = stats.statusStale;
  report_.statusAgeMs = stats.statusAgeMs;
  // Rates over the time between two reports, whatever their interval.
  GstClockTime now = pipeline_->runningTime();
  if (GST_CLOCK_TIME_IS_VALID(statsTime_) && now > statsTime_) {
    double seconds = static_cast<double>(now - statsTime_) / GST_SECOND;
    report_.fps = static_cast<double>(report_.frames - frames) / seconds;
    report_.kbps = static_cast<double>(report_.bytes - bytes) * 8 / 1000 / seconds;
  }
  statsTime_ = now;
  line["type"] = "stats";
  writeTelemetry(line, now);
}

void Camera::handlePosition(const GstStructure* s) {
  if (bus::is<bus::PositionStale>(s)) {
    auto stale = bus::PositionStale::read(s);
    logLine(name() + ": position of beacon " + std::to_string(stale.beacon) +
            " stale: " + stale.reason);
    report_.positionStale = stale.reason;
    nlohmann::json line = {
        {"type", "position-stale"}, {"beacon", stale.beacon}, {"reason", stale.reason}};
    writeTelemetry(line, pipeline_->runningTime());
    observer_.event(*this, line);
    return;
  }
  auto measured = bus::Position::read(s);
  // When it was measured (a position from before PLAYING has no running time).
  GstClockTime time = GST_CLOCK_TIME_IS_VALID(measured.runningTime) ? measured.runningTime
                                                                    : pipeline_->runningTime();
  Position position{.beacon = measured.beacon,
                    .x = measured.x,
                    .y = measured.y,
                    .z = measured.z,
                    .unixMs = unixMsOf(pipeline_->pipeline(), time)};
  report_.position = position;
  report_.positionStale.clear();
  trail_.push_back(position);
  if (trail_.size() > kTrailPositions) trail_.pop_front();
  // Until a frame opens the first file, where the vehicle is belongs to no
  // recording (and must not crowd the session events out of the early lines).
  if (!pipeline_->hasFrames()) return;
  writeTelemetry({{"type", "position"},
                  {"beacon", position.beacon},
                  {"x", position.x},
                  {"y", position.y},
                  {"z", position.z}},
                 time);
}

void Camera::handleElementMessage(GstMessage* message) {
  const GstStructure* s = gst_message_get_structure(message);
  if (!s || !pipeline_) return;
  // The files the SegmentWriter opens and finishes.
  if (gst_structure_has_name(s, SegmentFile::kOpenedMessage)) {
    report_.segment = gst_structure_get_string(s, "location");
    pipeline_->telemetry().segmentOpened(report_.segment);
    if (auto failure = pipeline_->telemetry().takeWriteFailure()) logLine(*failure);
    return;
  }
  if (gst_structure_has_name(s, SegmentFile::kClosedMessage)) {
    std::string file = gst_structure_get_string(s, "location");
    // (Finished on a streaming thread: the next file may be open already.)
    if (file == report_.segment) report_.segment.clear();
    pipeline_->writer().finished(file, machine_.phase() == CameraPhase::kRunning);
    closed(file);
    return;
  }

  nlohmann::json line = toJson(s);
  if (bus::is<bus::Session>(s)) return handleSession(s, std::move(line));
  if (bus::is<bus::Stats>(s)) return handleStats(s, std::move(line));
  if (bus::is<bus::Position>(s) || bus::is<bus::PositionStale>(s)) return handlePosition(s);
  if (bus::is<bus::Vehicle>(s)) {
    // The steered vehicle's own link (RCOIP, BTEMP, or WiRC) and its status
    // reports: battery, RSSI, pins.
    auto vehicle = bus::Vehicle::read(s);
    if (vehicle.state)
      logLine(name() + ": vehicle " + printableText(vehicle.event) + " (" + *vehicle.state + ")");
    line["type"] = "vehicle";
    writeTelemetry(line, pipeline_->runningTime());
    if (vehicle.state) observer_.event(*this, line);  // link changes, not each report
    return;
  }
  if (bus::is<bus::Drive>(s)) {
    // Driving by hand from the page: each command, and the dead-man's neutral.
    line["type"] = "drive";
    if (line.value("reason", "") == "dead-man") ++report_.deadManLapses;
    writeTelemetry(line, pipeline_->runningTime());
    return;
  }
  bool detections = bus::is<bus::AprilTags>(s);
  if (!detections && !bus::is<bus::Control>(s)) return;
  // Detections and commands belong to a frame: its timestamp is their time.
  line["type"] = detections ? "detections" : "control";
  GstClockTime pts = bus::frameTimestamp(s);
  line.erase("timestamp");
  if (detections) observer_.detections(*this, line, unixMsOf(pipeline_->pipeline(), pts), pts);
  writeTelemetry(line, pts);
}

}  // namespace wircam::recorder
