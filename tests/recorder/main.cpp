#include <gst/gst.h>
#include <gtest/gtest.h>

int main(int argc, char** argv) {
  // The recorder finds the plugins itself; these tests only read files
  // back, with system plugins, through a registry of their own.
  g_setenv("GST_REGISTRY", WIRCAM_TEST_REGISTRY, TRUE);
  gst_init(&argc, &argv);
  ::testing::InitGoogleTest(&argc, argv);
  return RUN_ALL_TESTS();
}
