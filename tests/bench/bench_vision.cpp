// Decoding and detection cost.
//  - tjpegdec (GRAY8, I420) against GStreamer's jpegdec (I420) on the same
//    CIF and 720p JPEG frames, each in a GstHarness.
//  - AprilTag detection per frame on the simulator's follow sequence, with
//    recall beside each time: the library's defaults (quad_decimate 2),
//    full resolution (quad_decimate 1), and ROI tracking (windows at full
//    resolution, the whole frame every 10th frame).
#include <benchmark/benchmark.h>
#include <gst/check/gstharness.h>
#include <gst/gst.h>
#include <turbojpeg.h>

#include <memory>

#include "follow_scene.h"
#include "tag_tracker.h"

namespace {

using namespace wircam;

struct Size {
  int width;
  int height;
};

Size sizeArg(int64_t index) { return index == 0 ? Size{352, 288} : Size{1280, 720}; }

// A sequence from the follow scene: the target circles, the car stands.
struct Sequence {
  std::vector<std::vector<uint8_t>> jpegs;
  std::vector<std::vector<uint8_t>> grays;
  std::vector<bool> visible;
};

const Sequence& sequence(Size size) {
  static std::map<int, Sequence> cache;
  auto& s = cache[size.width];
  if (!s.jpegs.empty()) return s;
  auto scene = sim::FollowScene::create(
      {.width = size.width, .height = size.height, .path = sim::TargetPath::Circle});
  std::unique_ptr<void, decltype(&tjDestroy)> decoder(tjInitDecompress(), tjDestroy);
  for (int i = 0; i < 40; ++i) {
    (*scene)->step(0.25, {});
    s.jpegs.push_back((*scene)->renderJpeg(0));
    s.visible.push_back((*scene)->tagViews()[0].visible);
    std::vector<uint8_t> gray(static_cast<size_t>(size.width) * size.height);
    tjDecompress2(decoder.get(), s.jpegs.back().data(), s.jpegs.back().size(), gray.data(),
                  size.width, size.width, size.height, TJPF_GRAY, 0);
    s.grays.push_back(std::move(gray));
  }
  return s;
}

void decode(benchmark::State& state, const char* element, const char* format) {
  Size size = sizeArg(state.range(0));
  const auto& jpegs = sequence(size).jpegs;
  GstHarness* h = gst_harness_new(element);
  gchar* caps =
      g_strdup_printf("image/jpeg,width=%d,height=%d,framerate=15/1", size.width, size.height);
  gst_harness_set_src_caps_str(h, caps);
  g_free(caps);
  gchar* sinkCaps = g_strdup_printf("video/x-raw,format=%s", format);
  gst_harness_set_sink_caps_str(h, sinkCaps);
  g_free(sinkCaps);
  std::vector<GstBuffer*> buffers;
  for (const auto& jpeg : jpegs) buffers.push_back(gst_buffer_new_memdup(jpeg.data(), jpeg.size()));
  size_t i = 0;
  GstClockTime pts = 0;
  for (auto _ : state) {
    GstBuffer* in = gst_buffer_copy(buffers[i++ % buffers.size()]);
    GST_BUFFER_PTS(in) = pts;
    pts += GST_SECOND / 15;
    if (gst_harness_push(h, in) != GST_FLOW_OK) {
      state.SkipWithError("push failed");
      break;
    }
    gst_buffer_unref(gst_harness_pull(h));
  }
  for (GstBuffer* b : buffers) gst_buffer_unref(b);
  gst_harness_teardown(h);
  state.counters["fps"] =
      benchmark::Counter(static_cast<double>(state.iterations()), benchmark::Counter::kIsRate);
}

void BM_TjpegDecGray8(benchmark::State& state) { decode(state, "tjpegdec", "GRAY8"); }
void BM_TjpegDecI420(benchmark::State& state) { decode(state, "tjpegdec", "I420"); }
void BM_JpegDecI420(benchmark::State& state) { decode(state, "jpegdec", "I420"); }

void detect(benchmark::State& state, float decimate, int fullFrameInterval) {
  Size size = sizeArg(state.range(0));
  const auto& seq = sequence(size);
  auto detector = vision::TagTracker::create({.quadDecimate = decimate},
                                             {.fullFrameInterval = fullFrameInterval});
  size_t i = 0, found = 0, visible = 0;
  for (auto _ : state) {
    size_t k = i++ % seq.grays.size();
    auto detections = detector->detect({seq.grays[k].data(), size.width, size.height, size.width});
    if (seq.visible[k]) {
      ++visible;
      for (const auto& d : detections) found += d.id == 0;
    }
  }
  state.counters["recall"] =
      visible ? static_cast<double>(found) / static_cast<double>(visible) : 0;
  state.counters["fps"] =
      benchmark::Counter(static_cast<double>(state.iterations()), benchmark::Counter::kIsRate);
}

void BM_DetectLibraryDefaults(benchmark::State& state) { detect(state, 2.0f, 1); }
void BM_DetectFullResolution(benchmark::State& state) { detect(state, 1.0f, 1); }
void BM_DetectRoiTracking(benchmark::State& state) { detect(state, 1.0f, 10); }

BENCHMARK(BM_TjpegDecGray8)->ArgName("720p")->Arg(0)->Arg(1);
BENCHMARK(BM_TjpegDecI420)->ArgName("720p")->Arg(0)->Arg(1);
BENCHMARK(BM_JpegDecI420)->ArgName("720p")->Arg(0)->Arg(1);
BENCHMARK(BM_DetectLibraryDefaults)->ArgName("720p")->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_DetectFullResolution)->ArgName("720p")->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_DetectRoiTracking)->ArgName("720p")->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond);

}  // namespace
