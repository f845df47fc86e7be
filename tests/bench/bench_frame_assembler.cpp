// Reassembly cost: wircam's FrameAssembler on WiRC datagrams against
// GStreamer's rtpjpegdepay on the RTP packets rtpjpegpay makes of the same
// JPEG frames at the same fragment size. Both run in-process: datagrams are
// prepared once, the loop measures only reassembly into whole frames.
#include <benchmark/benchmark.h>
#include <gst/check/gstharness.h>
#include <gst/gst.h>

#include <vector>

#include "synthetic_jpeg.h"
#include "wirc/frame_assembler.h"

namespace {

using wircam::wirc::AssembledFrame;
using wircam::wirc::FrameAssembler;

constexpr int kFrames = 64;  // distinct frames, pushed once per iteration
// rtpbasedepayload drops packets less than 100 sequence numbers behind the
// last one; each RTP iteration therefore spans more packets than that, so the
// jump back at its start reads as a sender restart, not as late packets.
constexpr size_t kMinRtpPacketsPerIteration = 200;

struct Resolution {
  int width;
  int height;
};

const std::vector<std::vector<uint8_t>>& frames(Resolution r) {
  static std::vector<std::vector<uint8_t>> cif, hd;
  auto& set = r.width == 352 ? cif : hd;
  if (set.empty())
    for (int i = 0; i < kFrames; ++i)
      set.push_back(wircam::bench::syntheticJpeg(r.width, r.height, i));
  return set;
}

Resolution resolutionArg(int64_t index) {
  return index == 0 ? Resolution{352, 288} : Resolution{1280, 720};
}

void reportRates(benchmark::State& state, size_t packets, size_t bytes, int64_t framesOut,
                 int framesPerIteration) {
  state.SetItemsProcessed(static_cast<int64_t>(state.iterations() * packets));
  state.SetBytesProcessed(static_cast<int64_t>(state.iterations() * bytes));
  state.counters["ns_per_byte"] =
      benchmark::Counter(static_cast<double>(state.iterations() * bytes) * 1e-9,
                         benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
  state.counters["frames_per_iter"] = static_cast<double>(framesOut) / state.iterations();
  state.counters["packets_per_frame"] = static_cast<double>(packets) / framesPerIteration;
}

void BM_WircamFrameAssembler(benchmark::State& state) {
  auto resolution = resolutionArg(state.range(0));
  auto fragment = static_cast<size_t>(state.range(1));
  std::vector<std::vector<uint8_t>> datagrams;
  size_t bytes = 0;
  for (int i = 0; i < kFrames; ++i) {
    const auto& jpeg = frames(resolution)[i];
    bytes += jpeg.size();
    for (auto& d : wircam::wirc::packetizeFrame(jpeg, static_cast<uint32_t>(i), fragment))
      datagrams.push_back(std::move(d));
  }

  FrameAssembler assembler;
  int64_t framesOut = 0;
  auto onFrame = [&](AssembledFrame&& frame) {
    ++framesOut;
    benchmark::DoNotOptimize(frame.data.data());
    assembler.recycle(std::move(frame.data));
  };
  auto now = FrameAssembler::Clock::now();
  for (auto _ : state) {
    assembler.reset();  // the same frame numbers again, as a new stream
    for (const auto& d : datagrams) assembler.pushDatagram(d, now, onFrame);
  }
  if (framesOut != state.iterations() * kFrames) state.SkipWithError("frames lost");
  reportRates(state, datagrams.size(), bytes, framesOut, kFrames);
}

// RTP/JPEG packets for the same frames, made by GStreamer's own payloader.
std::vector<GstBuffer*> rtpPackets(Resolution r, size_t fragment, size_t& bytes, int& framesIn) {
  GstHarness* pay = gst_harness_new("rtpjpegpay");
  // mtu counts the RTP header (12) and the RTP/JPEG main header (8).
  g_object_set(pay->element, "mtu", static_cast<guint>(fragment + 20), nullptr);
  gchar* caps = g_strdup_printf("image/jpeg,width=%d,height=%d,framerate=15/1", r.width, r.height);
  gst_harness_set_src_caps_str(pay, caps);
  g_free(caps);
  std::vector<GstBuffer*> packets;
  bytes = 0;
  for (framesIn = 0; framesIn % kFrames != 0 || packets.size() < kMinRtpPacketsPerIteration;
       ++framesIn) {
    const auto& jpeg = frames(r)[framesIn % kFrames];
    bytes += jpeg.size();
    GstBuffer* in = gst_buffer_new_memdup(jpeg.data(), jpeg.size());
    GST_BUFFER_PTS(in) = framesIn * GST_SECOND / 15;
    gst_harness_push(pay, in);
    while (GstBuffer* out = gst_harness_try_pull(pay)) packets.push_back(out);
  }
  gst_harness_teardown(pay);
  return packets;
}

void BM_GstRtpJpegDepay(benchmark::State& state) {
  auto resolution = resolutionArg(state.range(0));
  size_t bytes = 0;
  int framesIn = 0;
  auto packets = rtpPackets(resolution, static_cast<size_t>(state.range(1)), bytes, framesIn);

  GstHarness* depay = gst_harness_new("rtpjpegdepay");
  gst_harness_set_src_caps_str(
      depay, "application/x-rtp,media=video,clock-rate=90000,encoding-name=JPEG,payload=26");
  int64_t framesOut = 0;
  for (auto _ : state) {
    for (GstBuffer* packet : packets) gst_harness_push(depay, gst_buffer_ref(packet));
    while (GstBuffer* frame = gst_harness_try_pull(depay)) {
      ++framesOut;
      gst_buffer_unref(frame);
    }
  }
  gst_harness_teardown(depay);
  for (GstBuffer* packet : packets) gst_buffer_unref(packet);
  if (framesOut != state.iterations() * framesIn) state.SkipWithError("rtpjpegdepay lost frames");
  reportRates(state, packets.size(), bytes, framesOut, framesIn);
}

// {resolution: 0 = CIF, 1 = 720p, fragment size}
void Arguments(benchmark::internal::Benchmark* b) {
  b->ArgNames({"res", "fragment"});
  b->Args({0, 1400})->Args({1, 1400})->Args({0, 16000})->Args({1, 16000});
}

BENCHMARK(BM_WircamFrameAssembler)->Apply(Arguments)->Args({0, 64512})->Args({1, 64512});
BENCHMARK(BM_GstRtpJpegDepay)->Apply(Arguments);

}  // namespace
