// Runs the default GLib main context from the test's own thread until a
// condition holds: what a component on the main loop (a camera, a server,
// a WebSocket client) does in a test happens here.
#pragma once

#include <glib.h>

#include <chrono>
#include <functional>
#include <thread>

namespace wircam::testing {

// Runs the default main context until `done`, at most `limit`.
inline bool runMainLoopUntil(const std::function<bool()>& done,
                             std::chrono::milliseconds limit = std::chrono::seconds(5)) {
  auto until = std::chrono::steady_clock::now() + limit;
  while (!done()) {
    if (std::chrono::steady_clock::now() > until) return false;
    if (!g_main_context_iteration(nullptr, FALSE))
      std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  return true;
}

}  // namespace wircam::testing
