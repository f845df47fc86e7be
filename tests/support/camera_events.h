// A camera under test in this process: what it tells its supervisor, kept
// for the test to look at, and the main loop run (the camera's bus, its
// timers) until the test's condition holds.
#pragma once

#include <glib.h>

#include <chrono>
#include <functional>
#include <string>
#include <thread>
#include <utility>
#include <vector>

#include "camera/camera.h"

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

// Runs the default main context until `done`, at most `limit`.
inline bool runMainLoopUntil(const std::function<bool()>& done, std::chrono::milliseconds limit) {
  auto until = std::chrono::steady_clock::now() + limit;
  while (!done()) {
    if (std::chrono::steady_clock::now() > until) return false;
    if (!g_main_context_iteration(nullptr, FALSE))
      std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  return true;
}

}  // namespace wircam::testing
