// A reload: the options read again (the config file's present text, the
// command line's as it was) and applied per camera. Cameras added start,
// cameras removed finish their file and stop, cameras whose settings
// changed restart alone (Camera::replan); every other camera records on
// untouched. Refused with the reason, nothing changed, when the options do
// not validate or change what only a restart of the recorder can.
#include <algorithm>
#include <set>

#include "app/pipeline_planner.h"
#include "app/supervisor.h"
#include "log_line.h"

namespace wircam::recorder {

Expected<nlohmann::json, std::string> Supervisor::reload() {
  auto refuse = [](const std::string& why) {
    logLine("reload refused: " + why + "; nothing changed");
    return unexpected(why);
  };
  if (stopping_) return refuse("the recorder is stopping");
  if (options_.configFile.empty())
    return refuse(
        "there is no config file to read again (the recorder was started without --config)");
  auto reread = reread_();
  if (!reread) return refuse(reread.error());
  if (auto problem = reloadRefusal(options_, *reread)) return refuse(*problem);
  if (auto problem = checkFamily(reread->detectFamily)) return refuse(*problem);

  auto plan = planPipeline(*reread);
  if (auto problem = sameNamedStreams(plan)) return refuse(*problem);
  CameraFiles files = filesOf(*reread, plan);
  CameraHealth::Policy health = healthOf(*reread);
  // The new cameras are built first: one that cannot be refuses the reload
  // before any other camera is touched.
  std::vector<std::unique_ptr<Camera>> added;
  std::set<std::string> wanted;
  for (const auto& stream : plan.streams) {
    wanted.insert(stream.name);
    if (cameraNamed(stream.name)) continue;
    auto camera = Camera::create(stream, files, health, *this);
    if (!camera) return refuse(stream.name + ": " + camera.error());
    added.push_back(std::move(*camera));
  }
  nlohmann::json result = {{"added", nlohmann::json::array()},
                           {"removed", nlohmann::json::array()},
                           {"restarted", nlohmann::json::array()},
                           {"unchanged", nlohmann::json::array()}};
  for (auto& c : cameras_) {
    if (c->ended() || removing_.count(c.get())) continue;
    auto stream = std::find_if(plan.streams.begin(), plan.streams.end(),
                               [&](const StreamPlan& s) { return s.name == c->name(); });
    if (stream == plan.streams.end()) {
      result["removed"].push_back(c->name());
      removeCamera(*c);
    } else if (*stream != c->plannedNext() || files != c->files() || health != c->policy()) {
      result["restarted"].push_back(c->name());
      c->replan(*stream, files, health);
    } else {
      result["unchanged"].push_back(c->name());
    }
  }
  options_ = std::move(*reread);
  retention_.setLimits(retentionOf(options_));
  for (auto& camera : added) {
    result["added"].push_back(camera->name());
    Camera& fresh = *camera;
    cameras_.push_back(std::move(camera));
    addToServers(fresh);
    // Its namesake, removed a moment ago, may still be finishing its file
    // on the same device connection: it stops its stream when it ends,
    // which would stop this one's. This one starts after it.
    bool namesakeFinishing = std::any_of(removing_.begin(), removing_.end(),
                                         [&](Camera* c) { return c->name() == fresh.name(); });
    if (namesakeFinishing)
      startLater_.insert(&fresh);
    else if (!fresh.start())
      logLine(fresh.name() + ": its pipeline did not start");
  }
  enforceRetention();
  logLine("reloaded: " + std::to_string(result["added"].size()) + " camera(s) added, " +
          std::to_string(result["removed"].size()) + " removed, " +
          std::to_string(result["restarted"].size()) + " restarted with new settings, " +
          std::to_string(result["unchanged"].size()) + " recording on");
  return result;
}

void Supervisor::removeCamera(Camera& camera) {
  removing_.insert(&camera);
  removeFromServers(camera);
  camera.stop();  // ended() takes it out once its file is finished
}

void Supervisor::forgetEndedCameras() {
  std::erase_if(cameras_, [this](const std::unique_ptr<Camera>& c) {
    if (!c->ended() || !removing_.count(c.get())) return false;
    removing_.erase(c.get());
    startLater_.erase(c.get());  // removed again before it could start
    logLine(c->name() + ": removed by the reload");
    return true;
  });
  for (auto it = startLater_.begin(); it != startLater_.end();) {
    Camera* waiting = *it;
    bool namesakeFinishing = std::any_of(removing_.begin(), removing_.end(),
                                         [&](Camera* c) { return c->name() == waiting->name(); });
    if (namesakeFinishing || stopping_) {
      ++it;
      continue;
    }
    it = startLater_.erase(it);
    if (!waiting->start()) logLine(waiting->name() + ": its pipeline did not start");
  }
}

gboolean Supervisor::onReloadSignal(gpointer data) {
  static_cast<Supervisor*>(data)->reload();
  return G_SOURCE_CONTINUE;
}

}  // namespace wircam::recorder
