// main() of every benchmark program: GStreamer first (with the build tree's
// plugins on the path), then Google Benchmark.
#include <benchmark/benchmark.h>
#include <gst/gst.h>

int main(int argc, char** argv) {
  g_setenv("GST_PLUGIN_PATH", WIRCAM_PLUGIN_DIR, FALSE);
  gst_init(&argc, &argv);
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
