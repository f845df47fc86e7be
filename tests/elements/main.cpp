#include <gst/gst.h>
#include <gtest/gtest.h>

int main(int argc, char** argv) {
  // The plugins under test come from the build tree, with a registry of
  // their own so an installed wircam can never be picked up instead.
  g_setenv("GST_PLUGIN_PATH", WIRCAM_PLUGIN_DIR, TRUE);
  g_setenv("GST_REGISTRY", WIRCAM_TEST_REGISTRY, TRUE);
#if defined(__SANITIZE_ADDRESS__) || defined(__SANITIZE_THREAD__)
  // Sanitized plugins only load where the sanitizer runtime is: in this
  // process, not in GStreamer's separate plugin scanner.
  g_setenv("GST_REGISTRY_FORK", "no", TRUE);
#endif
  gst_init(&argc, &argv);
  // A GLib/GStreamer critical is a bug (a bad unmap, a wrong cast): the test
  // stops there instead of running on.
  g_log_set_always_fatal(static_cast<GLogLevelFlags>(G_LOG_LEVEL_CRITICAL | G_LOG_LEVEL_ERROR));
  ::testing::InitGoogleTest(&argc, argv);
  return RUN_ALL_TESTS();
}
