// How fast wirc-sim makes frames: the follow scene rendered (OpenCV), JPEG
// encoded (TurboJPEG) and sent as WiRC datagrams over loopback, at CIF and
// 720p. Beside it, GStreamer's own test source encoded by jpegenc
// (videotestsrc ! jpegenc ! fakesink) at the same sizes, as the stock
// alternative for producing a test JPEG stream.
#include <benchmark/benchmark.h>
#include <gst/gst.h>

#include "devices/wirc/stream_sender.h"
#include "follow_scene.h"

namespace {

using namespace wircam;

void BM_WircSimRenderEncodeSend(benchmark::State& state) {
  auto scene = sim::FollowScene::create(
      {.width = static_cast<int>(state.range(0)), .height = static_cast<int>(state.range(1))});
  auto sink = bindUdp(SocketAddress::loopback(0));
  auto source = bindUdp(SocketAddress::loopback(0));
  wirc::StreamSender sender(source->get(), -1, localAddress(sink->get()), 64512, {});
  size_t bytes = 0;
  for (auto _ : state) {
    (*scene)->step(1.0 / 15, {});
    auto jpeg = (*scene)->renderJpeg(0);
    bytes += jpeg.size();
    sender.sendFrame(jpeg);
  }
  state.counters["fps"] =
      benchmark::Counter(static_cast<double>(state.iterations()), benchmark::Counter::kIsRate);
  state.counters["jpeg_bytes"] = static_cast<double>(bytes) / state.iterations();
}

void BM_GstVideoTestSrcJpegEnc(benchmark::State& state) {
  constexpr int kFrames = 60;
  gchar* description = g_strdup_printf(
      "videotestsrc pattern=ball num-buffers=%d ! video/x-raw,width=%d,height=%d,framerate=15/1 ! "
      "jpegenc quality=85 ! fakesink sync=false",
      kFrames, static_cast<int>(state.range(0)), static_cast<int>(state.range(1)));
  for (auto _ : state) {
    GstElement* pipeline = gst_parse_launch(description, nullptr);
    gst_element_set_state(pipeline, GST_STATE_PLAYING);
    GstBus* bus = gst_element_get_bus(pipeline);
    GstMessage* done = gst_bus_timed_pop_filtered(
        bus, GST_CLOCK_TIME_NONE, static_cast<GstMessageType>(GST_MESSAGE_EOS | GST_MESSAGE_ERROR));
    if (GST_MESSAGE_TYPE(done) == GST_MESSAGE_ERROR) state.SkipWithError("pipeline error");
    gst_message_unref(done);
    gst_object_unref(bus);
    gst_element_set_state(pipeline, GST_STATE_NULL);
    gst_object_unref(pipeline);
  }
  g_free(description);
  state.counters["fps"] = benchmark::Counter(static_cast<double>(state.iterations() * kFrames),
                                             benchmark::Counter::kIsRate);
}

BENCHMARK(BM_WircSimRenderEncodeSend)
    ->ArgNames({"w", "h"})
    ->Args({352, 288})
    ->Args({1280, 720})
    ->UseRealTime();
BENCHMARK(BM_GstVideoTestSrcJpegEnc)
    ->ArgNames({"w", "h"})
    ->Args({352, 288})
    ->Args({1280, 720})
    ->UseRealTime()
    ->Unit(benchmark::kMillisecond);

}  // namespace
