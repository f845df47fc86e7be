// What a reload does to each camera, decided from what the cameras run and
// what the options now plan; the supervisor carries it out (Supervisor::
// reload). Pure: tested without a camera, a device or a clock.
#pragma once

#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "camera/camera_health.h"
#include "camera/camera_pipeline.h"
#include "camera/pipeline_plan.h"

namespace wircam::recorder {

// A camera as a reload sees it: what it runs, or will once a restart it
// was given is done. Cameras a reload removed, still finishing their file,
// are not among them.
struct RunningCamera {
  const StreamPlan& planned;
  const CameraFiles& files;
  const CameraHealth::Policy& policy;
};

struct ReloadPlan {
  std::vector<std::string> added;      // start (new streams, or a name back)
  std::vector<std::string> removed;    // finish their file and stop
  std::vector<std::string> restarted;  // their settings changed: restart alone
  std::vector<std::string> unchanged;  // record on, untouched

  // As POST /api/config/reload answers it.
  nlohmann::json summary() const;
};

// Cameras by name: a stream no camera runs is added, a camera whose stream
// is gone removed, one whose stream, files or health policy changed
// restarted; the rest unchanged.
ReloadPlan planReload(const std::vector<RunningCamera>& running,
                      const std::vector<StreamPlan>& streams, const CameraFiles& files,
                      const CameraHealth::Policy& health);

}  // namespace wircam::recorder
