// Control latency at CIF: from a frame's last packet arriving at wircsrc to
// the PCD that carries the command computed from it reaching the device.
//   frame pushed by wircsrc (pad probe; it pushes as the last packet lands)
//   → frame reaches wirccontrol (pad probe on its sink pad; it computes the
//     command and the link sends it from this thread when it changed)
//   → first PCD the simulated device receives after that (loopback: sent ≈ received)
// The same loop with GStreamer's jpegdec in place of tjpegdec runs beside it.
// Then a stalled pipeline (every buffer held 2 s): the longest PCD gap the
// device saw, which the keepalive bounds.
// Usage: bench_control_latency [SECONDS]   (default 10 per pipeline)
#include <gst/gst.h>

#include <algorithm>
#include <cstdio>
#include <map>
#include <mutex>
#include <thread>
#include <tuple>
#include <vector>

#include "bench_arguments.h"
#include "devices/wirc/device.h"
#include "follow_scene.h"

namespace {

using namespace wircam;
using Clock = std::chrono::steady_clock;

struct Probes {
  std::mutex mutex;
  std::map<GstClockTime, Clock::time_point> pushed;  // by PTS
  // (PTS, pushed, commanded) per frame that reached wirccontrol
  std::vector<std::tuple<GstClockTime, Clock::time_point, Clock::time_point>> commanded;
  std::map<GstClockTime, std::pair<guint, guint>> pulses;  // by PTS, from wirc-control
};

// wirc-control messages, as they are posted: which frames changed the command.
GstBusSyncReply onMessage(GstBus*, GstMessage* message, gpointer data) {
  const GstStructure* s = gst_message_get_structure(message);
  if (GST_MESSAGE_TYPE(message) == GST_MESSAGE_ELEMENT &&
      gst_structure_has_name(s, "wirc-control")) {
    auto* probes = static_cast<Probes*>(data);
    guint64 pts = 0;
    guint steering = 0, throttle = 0;
    gst_structure_get(s, "timestamp", G_TYPE_UINT64, &pts, "steering-pulse", G_TYPE_UINT, &steering,
                      "throttle-pulse", G_TYPE_UINT, &throttle, nullptr);
    std::lock_guard lock(probes->mutex);
    probes->pulses[pts] = {steering, throttle};
  }
  return GST_BUS_PASS;
}

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
    probes->commanded.emplace_back(found->first, found->second, now);
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
  auto attach = [&](const char* name, const char* padName, GstPadProbeCallback callback) {
    GstElement* element = gst_bin_get_by_name(GST_BIN(pipeline), name);
    GstPad* pad = gst_element_get_static_pad(element, padName);
    gst_pad_add_probe(pad, GST_PAD_PROBE_TYPE_BUFFER, callback, &probes, nullptr);
    gst_object_unref(pad);
    gst_object_unref(element);
  };
  GstBus* bus = gst_element_get_bus(pipeline);
  gst_bus_set_sync_handler(bus, onMessage, &probes, nullptr);
  gst_object_unref(bus);
  attach("src", "src", onPushed);
  attach("control", "sink", onCommanded);
  gst_element_set_state(pipeline, GST_STATE_PLAYING);
  std::this_thread::sleep_for(std::chrono::duration<double>(seconds));
  gst_element_set_state(pipeline, GST_STATE_NULL);
  gst_object_unref(pipeline);

  auto arrivals = device->pcdArrivals();
  // Only a frame whose command differs from the one before sends a PCD;
  // the others change nothing on the vehicle (keepalives repeat them).
  std::vector<double> processing, total;
  std::pair<guint, guint> previous{};
  for (auto [pts, pushed, commanded] : probes.commanded) {
    auto sent = probes.pulses.find(pts);
    if (sent == probes.pulses.end()) continue;
    bool changed = sent->second != previous;
    previous = sent->second;
    if (!changed) continue;
    auto pcd = std::upper_bound(arrivals.begin(), arrivals.end(), commanded);
    if (pcd == arrivals.end()) continue;
    processing.push_back(std::chrono::duration<double, std::milli>(commanded - pushed).count());
    total.push_back(std::chrono::duration<double, std::milli>(*pcd - pushed).count());
  }
  std::printf(
      "%-9s %6zu changes  frame → command median %5.2f ms p99 %5.2f ms   frame → PCD median "
      "%5.2f ms p99 %5.2f ms   longest PCD gap %lld ms\n",
      decoder, total.size(), percentile(processing, 0.5), percentile(processing, 0.99),
      percentile(total, 0.5), percentile(total, 0.99),
      static_cast<long long>(device->stats().maxPcdGap.count()));
}

// The streaming thread blocks 2 s on every buffer; the link's keepalives
// come from the event loop and must keep the device's watchdog fed.
void runStalled(double seconds) {
  auto device =
      std::move(*wirc::Device::start({.port = 0}, std::move(*sim::FollowScene::create({}))));
  auto port = std::to_string(device->port());
  GstElement* pipeline = gst_parse_launch(("wircsrc host=127.0.0.1 port=" + port +
                                           " ! tjpegdec ! apriltagdetect ! wirccontrol "
                                           "name=control host=127.0.0.1 port=" +
                                           port + " ! fakesink")
                                              .c_str(),
                                          nullptr);
  GstElement* control = gst_bin_get_by_name(GST_BIN(pipeline), "control");
  GstPad* pad = gst_element_get_static_pad(control, "src");
  gst_pad_add_probe(
      pad, GST_PAD_PROBE_TYPE_BUFFER,
      [](GstPad*, GstPadProbeInfo*, gpointer) {
        std::this_thread::sleep_for(std::chrono::seconds(2));
        return GST_PAD_PROBE_OK;
      },
      nullptr, nullptr);
  gst_element_set_state(pipeline, GST_STATE_PLAYING);
  std::this_thread::sleep_for(std::chrono::duration<double>(seconds));
  auto stats = device->stats();
  std::printf(
      "stalled   %6llu PCD received   longest PCD gap %lld ms (keepalive 100 ms, device "
      "timeout 800 ms)   watchdog fired %llu times\n",
      static_cast<unsigned long long>(stats.pcdReceived),
      static_cast<long long>(stats.maxPcdGap.count()),
      static_cast<unsigned long long>(stats.failsafeEntries));
  gst_element_set_state(pipeline, GST_STATE_NULL);
  gst_object_unref(pad);
  gst_object_unref(control);
  gst_object_unref(pipeline);
}

}  // namespace

int main(int argc, char** argv) {
  g_setenv("GST_PLUGIN_PATH", WIRCAM_PLUGIN_DIR, FALSE);
  gst_init(&argc, &argv);
  auto arguments = wircam::bench::positiveArguments(
      argc, argv, {10}, "usage: bench_control_latency [SECONDS]   (per pipeline, default 10)");
  if (!arguments) return 2;
  double seconds = (*arguments)[0];
  std::printf("CIF, 15 fps; a changed command leaves at once, keepalive every 100 ms\n");
  run("tjpegdec", seconds);
  run("jpegdec", seconds);
  runStalled(seconds);
  return 0;
}
