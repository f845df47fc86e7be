// A camera under test in this process: what it tells its supervisor, kept
// for the test to look at, and the main loop run (the camera's bus, its
// timers) until the test's condition holds.
#pragma once

#include <string>
#include <utility>
#include <vector>

#include "camera/camera.h"
#include "main_loop_until.h"

namespace wircam::testing {

struct CameraEvents : recorder::CameraObserver {
  std::vector<std::pair<std::string, recorder::PlannedSegment>> closed;  // file, as planned
  bool over = false;
  void segmentClosed(recorder::Camera&, const std::string& file,
                     const recorder::PlannedSegment& planned) override {
    closed.emplace_back(file, planned);
  }
  void event(recorder::Camera&, const nlohmann::json&) override {}
  void detections(recorder::Camera&, const nlohmann::json&, int64_t, GstClockTime) override {}
  void diskFull(recorder::Camera&) override {}
  void ended(recorder::Camera&) override { over = true; }
};

}  // namespace wircam::testing
