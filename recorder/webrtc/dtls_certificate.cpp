#include "webrtc/dtls_certificate.h"

#include <gst/gst.h>

#include <atomic>
#include <chrono>
#include <mutex>
#include <string>
#include <thread>

#include "log_line.h"

namespace wircam::recorder::dtls_certificate {

namespace {

enum class Progress { NotStarted, Making, Made };
std::atomic<Progress> progress{Progress::NotStarted};
std::once_flag started;

}  // namespace

void makeAhead() {
  std::call_once(started, [] {
    progress = Progress::Making;
    // Detached: its state is this file's, which outlives every caller.
    std::thread([] {
      auto begun = std::chrono::steady_clock::now();
      if (GstElement* dtls = gst_element_factory_make("dtlsdec", nullptr)) gst_object_unref(dtls);
      auto took = std::chrono::duration_cast<std::chrono::milliseconds>(
          std::chrono::steady_clock::now() - begun);
      logLine("webrtc: DTLS certificate made in " + std::to_string(took.count()) + " ms");
      progress = Progress::Made;
    }).detach();
  });
}

bool made() { return progress == Progress::Made; }

bool beingMade() { return progress == Progress::Making; }

}  // namespace wircam::recorder::dtls_certificate
