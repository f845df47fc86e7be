#include "status/camera_report.h"

#include <cmath>
#include <cstdio>
#include <filesystem>

#include "record/segment_planner.h"

namespace wircam::recorder {

namespace {
double tenths(double value) { return std::round(value * 10) / 10; }
}  // namespace

double lossPercent(const CameraReport& c) {
  double total = static_cast<double>(c.frames + c.incomplete);
  return total > 0 ? 100.0 * static_cast<double>(c.incomplete) / total : 0.0;
}

nlohmann::json positionJson(const CameraReport& c) {
  nlohmann::json position = nullptr;
  bool stale = !c.positionStale.empty();
  if (c.position)
    position = {{"beacon", c.position->beacon},
                {"x", c.position->x},
                {"y", c.position->y},
                {"z", c.position->z},
                {"utc", SegmentPlanner::isoUtc(c.position->unixMs)},
                {"stale", stale}};
  else if (stale)
    position = {{"stale", true}};  // none came: say why
  if (stale) position["stale_reason"] = c.positionStale;
  return position;
}

nlohmann::json statusJson(const CameraReport& c, const std::string& rtsp) {
  nlohmann::json stream = {{"name", c.name},
                           {"device", c.device},
                           {"camera", c.camera},
                           {"state", c.state},
                           {"state_since_utc", SegmentPlanner::isoUtc(c.stateSinceUnixMs)},
                           {"link_reason", c.linkReason},
                           {"restarts", c.restarts},
                           {"frames", c.frames},
                           {"recording_dropped", c.recordingDropped},
                           {"fps", c.fps},
                           {"loss_percent", lossPercent(c)},
                           {"kbps", c.kbps},
                           {"battery_v", c.batteryMv / 1000.0},
                           {"status_stale", c.statusStale},
                           {"status_age_ms", c.statusAgeMs},
                           {"segment", std::filesystem::path(c.segment).filename().string()},
                           {"live", "/live/" + c.name + ".mjpg"}};
  if (c.control) {
    stream["has_control"] = c.control->hasControl;
    stream["following"] = c.control->following;
    stream["target"] = c.control->target;
  }
  if (c.positions) stream["position"] = positionJson(c);
  if (!rtsp.empty()) stream["rtsp"] = rtsp;
  return stream;
}

nlohmann::json cameraJson(const CameraReport& c) {
  auto control = c.control.value_or(ControlReport{});
  return {{"name", c.name},
          {"state", c.state},
          {"fps", tenths(c.fps)},
          {"has_control", control.hasControl},
          {"following", control.following}};
}

nlohmann::json fleetStatusJson(const CameraReport& c) {
  auto control = c.control.value_or(ControlReport{});
  return {{"state", c.state},
          {"state_since_utc", SegmentPlanner::isoUtc(c.stateSinceUnixMs)},
          {"fps", tenths(c.fps)},
          {"loss", tenths(lossPercent(c))},
          {"battery_v", c.batteryMv / 1000.0},
          {"has_control", control.hasControl},
          {"following", control.following},
          {"target", control.target},
          {"position", positionJson(c)}};
}

nlohmann::json trailJson(const std::deque<Position>& trail, bool stale) {
  nlohmann::json points = nlohmann::json::array();
  for (const auto& p : trail)
    points.push_back({{"x", p.x}, {"y", p.y}, {"utc", SegmentPlanner::isoUtc(p.unixMs)}});
  return {{"points", points}, {"stale", stale}};
}

std::string statusLine(const CameraReport& c) {
  char line[512];
  if (c.state == "connecting" && !c.everLive) {
    std::snprintf(line, sizeof line, "%-20s waiting for device", c.name.c_str());
    return line;
  }
  // A device that stopped reporting keeps its last battery reading, marked.
  std::string stale =
      c.statusStale ? " (stale, " + std::to_string(c.statusAgeMs / 1000) + " s old)" : "";
  std::string where;
  if (c.position) {
    char text[64];
    std::snprintf(text, sizeof text, "  at %.2f, %.2f m%s", c.position->x, c.position->y,
                  c.positionStale.empty() ? "" : " (stale)");
    where = text;
  }
  std::string state = c.state == "live" ? "" : "  [" + c.state + "]";
  std::snprintf(
      line, sizeof line,
      "%-20s %7llu frames %5.1f fps  loss %4.1f%%  %7.0f kbit/s  battery %5.2f V%s%s  %s%s",
      c.name.c_str(), static_cast<unsigned long long>(c.frames), c.fps, lossPercent(c), c.kbps,
      c.batteryMv / 1000.0, stale.c_str(), where.c_str(),
      std::filesystem::path(c.segment).filename().c_str(), state.c_str());
  return line;
}

}  // namespace wircam::recorder
