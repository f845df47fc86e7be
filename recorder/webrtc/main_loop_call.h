// Work handed from a GStreamer thread (webrtcbin's signals and promises) to
// the main loop, where the recorder's objects live; dropped if the object
// it was for has gone by then.
#pragma once

#include <glib.h>

#include <functional>
#include <memory>

namespace wircam::recorder {

inline void callOnMainLoop(std::weak_ptr<void> alive, std::function<void()> call) {
  struct Job {
    std::weak_ptr<void> alive;
    std::function<void()> call;
  };
  g_main_context_invoke_full(
      nullptr, G_PRIORITY_DEFAULT,
      [](gpointer data) -> gboolean {
        auto* job = static_cast<Job*>(data);
        if (auto held = job->alive.lock()) job->call();
        return G_SOURCE_REMOVE;
      },
      new Job{std::move(alive), std::move(call)},
      [](gpointer data) { delete static_cast<Job*>(data); });
}

}  // namespace wircam::recorder
