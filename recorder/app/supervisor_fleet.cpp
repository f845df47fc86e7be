// The supervisor's part in the fleet: each live device asked who its
// vehicle is, and the announcement of this recorder (fleet_announcement.h).
#include <unistd.h>

#include "app/supervisor.h"

namespace wircam::recorder {

namespace {

std::string hostName() {
  char host[256] = "localhost";
  gethostname(host, sizeof host - 1);
  return host;
}

}  // namespace

void Supervisor::identify(Camera& camera) {
  vehicles_.ask(camera.plan().device, camera.plan().host, camera.plan().port);
}

nlohmann::json Supervisor::withVehicle(nlohmann::json entry, const Camera& camera) const {
  entry["vehicle"] = toJson(vehicles_.of(camera.plan().device));
  return entry;
}

void Supervisor::announce() {
  if (!fleet_) return;
  announcedAt_ = g_get_monotonic_time() / 1000;
  std::string host = hostName();
  Announcement announcement{.id = recorderId_,
                            .host = host,
                            .version = WIRCAM_VERSION,
                            .mqttPrefix = options_.mqttPrefix,
                            .webrtc = http_ && options_.webrtc,
                            .seenUnixMs = g_get_real_time() / 1000};
  if (http_) announcement.http = fleetHttpUrl(http_->url(), options_.fleetUrl, host);
  if (rtsp_) announcement.rtsp = fleetServiceUrl(rtsp_->url(), options_.fleetUrl, host);
  if (foxglove_) announcement.foxglove = fleetServiceUrl(foxglove_->url(), options_.fleetUrl, host);
  for (const auto& c : cameras_) {
    if (removing_.count(c.get())) continue;
    const auto& plan = c->plan();
    // Its path on the RTSP server, when there is one to play it from.
    std::string rtspPath =
        rtsp_ ? "/" + plan.device + "/cam" + std::to_string(plan.camera) : std::string();
    announcement.cameras.push_back({c->name(), vehicles_.of(plan.device), rtspPath});
  }
  fleet_->announce(announcement);
}

}  // namespace wircam::recorder
