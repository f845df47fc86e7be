// Control latency at CIF: from a frame's last packet arriving at wircsrc to
// the PCD that carries the command computed from it reaching the device.
//   frame pushed by wircsrc (pad probe; it pushes as the last packet lands)
//   → command set by wirccontrol (pad probe after it)
//   → first PCD the simulated device receives after that (loopback: sent ≈ received)
// The same loop with GStreamer's jpegdec in place of tjpegdec runs beside it.
// Usage: bench_control_latency [SECONDS]   (default 10 per pipeline)
#include <gst/gst.h>

#include <algorithm>
#include <cstdio>
#include <map>
#include <mutex>
#include <thread>
#include <vector>

#include "follow_scene.h"
#include "wirc/device.h"

namespace {

using namespace wircam;
using Clock = std::chrono::steady_clock;

struct Probes {
  std::mutex mutex;
  std::map<GstClockTime, Clock::time_point> pushed;                        // by PTS
  std::vector<std::pair<Clock::time_point, Clock::time_point>> commanded;  // (pushed, commanded)
};

GstPadProbeReturn onPushed(GstPad*, GstPadProbeInfo* info, gpointer data) {
  auto* probes = static_cast<Probes*>(data);
  std::lock_guard lock(probes->mutex);
  probes->pushed[GST_BUFFER_PTS(GST_PAD_PROBE_INFO_BUFFER(info))] = Clock::now();
  return GST_PAD_PROBE_OK;
}

GstPadProbeReturn onCommanded(GstPad*, GstPadProbeInfo* info, gpointer data) {
  auto* probes = static_cast<Probes*>(data);
  auto now = Clock::now();
  std::lock_guard lock(probes->mutex);
  auto found = probes->pushed.find(GST_BUFFER_PTS(GST_PAD_PROBE_INFO_BUFFER(info)));
  if (found != probes->pushed.end()) {
    probes->commanded.emplace_back(found->second, now);
    probes->pushed.erase(found);
  }
  return GST_PAD_PROBE_OK;
}

double percentile(std::vector<double> values, double p) {
  if (values.empty()) return 0;
  std::sort(values.begin(), values.end());
  return values[std::min(values.size() - 1,
                         static_cast<size_t>(p * static_cast<double>(values.size())))];
}

void run(const char* decoder, double seconds) {
  auto scene = std::move(*sim::FollowScene::create({}));
  auto device = std::move(*wirc::Device::start({.port = 0}, std::move(scene)));
  auto port = std::to_string(device->port());
  std::string description =
      "wircsrc name=src host=127.0.0.1 port=" + port + " ! " + decoder +
      " ! video/x-raw,format=I420 ! apriltagdetect quad-decimate=1 ! wirccontrol name=control "
      "host=127.0.0.1 port=" +
      port + " ! fakesink";
  GstElement* pipeline = gst_parse_launch(description.c_str(), nullptr);
  Probes probes;
  auto attach = [&](const char* name, GstPadProbeCallback callback) {
    GstElement* element = gst_bin_get_by_name(GST_BIN(pipeline), name);
    GstPad* pad = gst_element_get_static_pad(element, "src");
    gst_pad_add_probe(pad, GST_PAD_PROBE_TYPE_BUFFER, callback, &probes, nullptr);
    gst_object_unref(pad);
    gst_object_unref(element);
  };
  attach("src", onPushed);
  attach("control", onCommanded);
  gst_element_set_state(pipeline, GST_STATE_PLAYING);
  std::this_thread::sleep_for(std::chrono::duration<double>(seconds));
  gst_element_set_state(pipeline, GST_STATE_NULL);
  gst_object_unref(pipeline);

  auto arrivals = device->pcdArrivals();
  std::vector<double> processing, total;
  for (auto [pushed, commanded] : probes.commanded) {
    auto pcd = std::upper_bound(arrivals.begin(), arrivals.end(), commanded);
    if (pcd == arrivals.end()) continue;
    processing.push_back(std::chrono::duration<double, std::milli>(commanded - pushed).count());
    total.push_back(std::chrono::duration<double, std::milli>(*pcd - pushed).count());
  }
  std::printf(
      "%-9s %6zu frames   processing median %5.2f ms p99 %5.2f ms   to PCD median %5.2f ms p99 "
      "%5.2f ms\n",
      decoder, total.size(), percentile(processing, 0.5), percentile(processing, 0.99),
      percentile(total, 0.5), percentile(total, 0.99));
}

}  // namespace

int main(int argc, char** argv) {
  g_setenv("GST_PLUGIN_PATH", WIRCAM_PLUGIN_DIR, FALSE);
  gst_init(&argc, &argv);
  double seconds = argc > 1 ? std::atof(argv[1]) : 10;
  std::printf("CIF, 15 fps, PCD at 50 Hz (a command waits up to 20 ms for the next PCD)\n");
  run("tjpegdec", seconds);
  run("jpegdec", seconds);
  return 0;
}
