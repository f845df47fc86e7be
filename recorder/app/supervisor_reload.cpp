// A reload: the options read again (the config file's present text, the
// command line's as it was) and applied per camera. Cameras added start,
// cameras removed finish their file and stop, cameras whose settings
// changed restart alone (Camera::replan); every other camera records on
// untouched. Refused with the reason, nothing changed, when the options do
// not validate or change what only a restart of the recorder can.
#include <algorithm>

#include "app/open_files_check.h"
#include "app/pipeline_planner.h"
#include "app/reload_plan.h"
#include "app/supervisor.h"
#include "common/open_file_limit.h"
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

  if (auto problem = cameraRecordedTwice(*reread)) return refuse(*problem);
  auto plan = planPipeline(*reread);
  if (auto problem = sameNamedStreams(plan)) return refuse(*problem);
  CameraFiles files = filesOf(*reread, plan);
  CameraHealth::Policy health = healthOf(*reread);
  std::vector<Camera*> running;
  std::vector<RunningCamera> seen;
  for (auto& c : cameras_) {
    if (c->ended() || removing_.count(c.get())) continue;
    running.push_back(c.get());
    seen.push_back({c->plannedNext(), c->files(), c->policy()});
  }
  ReloadPlan changes = planReload(seen, plan.streams, files, health);
  auto among = [](const std::vector<std::string>& names, const std::string& name) {
    return std::find(names.begin(), names.end(), name) != names.end();
  };
  // The new cameras are built first: one that cannot be refuses the reload
  // before any other camera is touched.
  std::vector<std::unique_ptr<Camera>> added;
  for (const auto& stream : plan.streams) {
    if (!among(changes.added, stream.name)) continue;
    auto camera = Camera::create(stream, files, health, *this);
    if (!camera) return refuse(stream.name + ": " + camera.error());
    added.push_back(std::move(*camera));
  }
  for (Camera* c : running) {
    if (among(changes.removed, c->name())) {
      removeCamera(*c);
    } else if (among(changes.restarted, c->name())) {
      auto stream = std::find_if(plan.streams.begin(), plan.streams.end(),
                                 [&](const StreamPlan& s) { return s.name == c->name(); });
      c->replan(*stream, files, health);
    }
  }
  options_ = std::move(*reread);
  retention_.setLimits(retentionOf(options_));
  if (!added.empty())
    if (auto shortfall = openFilesShortfall(plan.streams.size(), raiseOpenFileLimit()))
      logLine("reload: " + *shortfall);
  for (auto& camera : added) {
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
  logLine("reloaded: " + std::to_string(changes.added.size()) + " camera(s) added, " +
          std::to_string(changes.removed.size()) + " removed, " +
          std::to_string(changes.restarted.size()) + " restarted with new settings, " +
          std::to_string(changes.unchanged.size()) + " recording on");
  return changes.summary();
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
