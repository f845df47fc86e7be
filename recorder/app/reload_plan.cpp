#include "app/reload_plan.h"

#include <algorithm>

namespace wircam::recorder {

nlohmann::json ReloadPlan::summary() const {
  return {
      {"added", added}, {"removed", removed}, {"restarted", restarted}, {"unchanged", unchanged}};
}

ReloadPlan planReload(const std::vector<RunningCamera>& running,
                      const std::vector<StreamPlan>& streams, const CameraFiles& files,
                      const CameraHealth::Policy& health) {
  ReloadPlan plan;
  for (const auto& stream : streams) {
    bool runs = std::any_of(running.begin(), running.end(),
                            [&](const RunningCamera& c) { return c.planned.name == stream.name; });
    if (!runs) plan.added.push_back(stream.name);
  }
  for (const auto& camera : running) {
    auto stream = std::find_if(streams.begin(), streams.end(),
                               [&](const StreamPlan& s) { return s.name == camera.planned.name; });
    if (stream == streams.end())
      plan.removed.push_back(camera.planned.name);
    else if (*stream != camera.planned || files != camera.files || health != camera.policy)
      plan.restarted.push_back(camera.planned.name);
    else
      plan.unchanged.push_back(camera.planned.name);
  }
  return plan;
}

}  // namespace wircam::recorder
