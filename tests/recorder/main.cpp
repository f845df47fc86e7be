#include <gst/gst.h>
#include <gtest/gtest.h>

#include <chrono>
#include <thread>

#include "webrtc/dtls_certificate.h"

int main(int argc, char** argv) {
  // These tests read files back with system plugins, through a registry of
  // their own, which the recorders they start share. A recorder adds the
  // build's plugins to the path; so does this process: with two plugin
  // sets, each recorder added them to the registry and each test's start
  // took them out again, a scan and a rewrite each time.
  g_setenv("GST_PLUGIN_PATH", WIRCAM_PLUGIN_DIR, TRUE);
  g_setenv("GST_REGISTRY", WIRCAM_TEST_REGISTRY, TRUE);
  gst_init(&argc, &argv);
  ::testing::InitGoogleTest(&argc, argv);
  int code = RUN_ALL_TESTS();
  // The in-process WebRTC tests' DTLS key, if it is still being made: exit's
  // handlers would take libcrypto down under its thread (a test may wait).
  while (wircam::recorder::dtls_certificate::beingMade())
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  return code;
}
