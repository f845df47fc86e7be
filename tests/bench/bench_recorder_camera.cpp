// What one camera's recording costs a frame in this process, its threads
// and the disk's writer's included (the process's CPU time): the recorder's
// own Camera (its pipeline, segment writer, matroskamux, the filesystem's
// DiskWriter), with its text track and without, and without the DiskWriter
// (--record-queue 0), beside the stock
//   appsrc ! matroskamux ! filesink
// on the same 30 s of the follow scene's CIF frames (15 fps), pushed as
// fast as they are taken, from the first frame until the source has handed
// on the last (starts and stops are not timed). The text track gets a line
// a second of video, as the link's statistics come. No sockets and no
// other process, so the figures move less from run to run than
// bench_recorder_streams' do.
#include <benchmark/benchmark.h>
#include <gst/app/gstappsrc.h>
#include <gst/check/gsttestclock.h>
#include <gst/gst.h>
#include <unistd.h>

#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>

#include "appsrc_camera_plan.h"
#include "camera/camera.h"
#include "camera/camera_pipeline.h"
#include "camera_events.h"
#include "scene_frames.h"

namespace {

namespace fs = std::filesystem;
using namespace wircam::recorder;
using wircam::testing::runMainLoopUntil;
using wircam::testing::sceneFrames;

constexpr int kFrames = 450;
constexpr GstClockTime kFrameInterval = GST_SECOND / 15;
constexpr uint64_t kRecordQueue = 8 << 20;  // the recorder's default --record-queue

// A folder of its own for what one benchmark records, emptied by each
// iteration (a camera names its files by the second: 450 frames an
// iteration filled hundreds of MB a run) and removed at the end.
struct BenchFolder {
  explicit BenchFolder(const char* name)
      : path(fs::temp_directory_path() /
             ("wircam-bench-camera-" + std::to_string(getpid()) + "-" + name)) {
    empty();
  }
  ~BenchFolder() { fs::remove_all(path); }
  void empty() const {
    fs::remove_all(path);
    fs::create_directories(path);
  }
  fs::path path;
};

GstBuffer* frame(int index) {
  const auto& jpeg = sceneFrames()[index % sceneFrames().size()];
  GstBuffer* buffer = gst_buffer_new_memdup(jpeg.data(), jpeg.size());
  GST_BUFFER_PTS(buffer) = GST_BUFFER_DTS(buffer) = index * kFrameInterval;
  GST_BUFFER_DURATION(buffer) = kFrameInterval;
  return buffer;
}

// The recorder's plan for a camera whose source is an appsrc, the test's.
StreamPlan cameraPlan(bool textTrack, uint64_t recordQueue) {
  StreamPlan plan = wircam::testing::appSrcCameraPlan();
  plan.recordBound = recordQueue;
  if (textTrack) wircam::testing::addTextTrack(plan);
  return plan;
}

// `recordQueue` 0: the camera writes its files itself (filesink), as with
// --record-queue 0; else through the filesystem's DiskWriter.
void recordCamera(benchmark::State& state, bool textTrack, uint64_t recordQueue) {
  BenchFolder folder(textTrack ? "text" : recordQueue ? "notext" : "noqueue");
  for (auto _ : state) {
    state.PauseTiming();  // the camera's start is not a frame's cost
    folder.empty();
    wircam::testing::CameraEvents observed;
    GstElement* source = nullptr;
    GstClock* clock = nullptr;
    // As the recorder builds it, on a test clock: a line's time is the
    // video's, not how fast the frames are pushed.
    Camera::PipelineBuilder builder = [&](const StreamPlan& stream, const CameraFiles& files,
                                          FrameTap* frames, FrameTap* encoded) {
      auto pipeline = CameraPipeline::build(stream, files, frames, encoded);
      if (pipeline) {
        clock = gst_test_clock_new();
        gst_pipeline_use_clock(GST_PIPELINE((*pipeline)->pipeline()), clock);
        gst_object_unref(clock);
        source = GST_ELEMENT(gst_object_ref((*pipeline)->element("src")));
      }
      return pipeline;
    };
    CameraFiles files{.folder = folder.path.string(), .extension = ".mkv", .limits = {}};
    auto camera = Camera::create(cameraPlan(textTrack, recordQueue), files, {}, observed, builder);
    if (!camera || !(*camera)->start() || !source) {
      state.SkipWithError("the camera did not start");
      return;
    }
    state.ResumeTiming();
    for (int i = 0; i < kFrames; ++i) {
      if (textTrack && i % 15 == 0) {
        gst_test_clock_set_time(GST_TEST_CLOCK(clock), i * kFrameInterval);
        (*camera)->writeTelemetry({{"type", "stats"}, {"frames-complete", i}});
      }
      gst_app_src_push_buffer(GST_APP_SRC(source), frame(i));
    }
    runMainLoopUntil(
        [&] { return gst_app_src_get_current_level_buffers(GST_APP_SRC(source)) == 0; },
        std::chrono::seconds(60));
    // Nor its stop. With a text track the lines still due go in with the
    // next frame, as a live camera's keep coming (without one, the camera
    // would wait SegmentWriter::kTextDrain, 300 ms, for it).
    state.PauseTiming();
    (*camera)->stop();
    gst_app_src_push_buffer(GST_APP_SRC(source), frame(kFrames));
    if (!runMainLoopUntil([&] { return observed.over; }, std::chrono::seconds(60))) {
      state.SkipWithError("the camera did not end");
      return;
    }
    gst_object_unref(source);
    state.ResumeTiming();
  }
  state.SetItemsProcessed(state.iterations() * kFrames);
}

void BM_RecorderCamera(benchmark::State& state) { recordCamera(state, true, kRecordQueue); }
void BM_RecorderCameraNoTextTrack(benchmark::State& state) {
  recordCamera(state, false, kRecordQueue);
}
void BM_RecorderCameraNoTextTrackNoQueue(benchmark::State& state) { recordCamera(state, false, 0); }

void BM_StockMatroskaFile(benchmark::State& state) {
  BenchFolder folder("stock");  // one file, written over by each iteration
  std::string description = std::string(wircam::testing::kAppSrcCamera) +
                            " ! matroskamux ! filesink location=\"" +
                            (folder.path / "stock.mkv").string() + "\"";
  for (auto _ : state) {
    state.PauseTiming();
    GstElement* pipeline = gst_parse_launch(description.c_str(), nullptr);
    GstElement* source = gst_bin_get_by_name(GST_BIN(pipeline), "src");
    gst_element_set_state(pipeline, GST_STATE_PLAYING);
    state.ResumeTiming();
    for (int i = 0; i < kFrames; ++i) gst_app_src_push_buffer(GST_APP_SRC(source), frame(i));
    runMainLoopUntil(
        [&] { return gst_app_src_get_current_level_buffers(GST_APP_SRC(source)) == 0; },
        std::chrono::seconds(60));
    state.PauseTiming();
    gst_app_src_end_of_stream(GST_APP_SRC(source));
    GstBus* bus = gst_element_get_bus(pipeline);
    GstMessage* end = gst_bus_timed_pop_filtered(
        bus, 60 * GST_SECOND, static_cast<GstMessageType>(GST_MESSAGE_EOS | GST_MESSAGE_ERROR));
    if (!end || GST_MESSAGE_TYPE(end) != GST_MESSAGE_EOS) state.SkipWithError("no end of stream");
    if (end) gst_message_unref(end);
    gst_object_unref(bus);
    gst_element_set_state(pipeline, GST_STATE_NULL);
    gst_object_unref(source);
    gst_object_unref(pipeline);
    state.ResumeTiming();
  }
  state.SetItemsProcessed(state.iterations() * kFrames);
}

}  // namespace

// The process's CPU time: the pipelines' threads and the disk's writer do
// the work, not the one that pushes.
BENCHMARK(BM_StockMatroskaFile)->MeasureProcessCPUTime()->Unit(benchmark::kMillisecond);
BENCHMARK(BM_RecorderCamera)->MeasureProcessCPUTime()->Unit(benchmark::kMillisecond);
BENCHMARK(BM_RecorderCameraNoTextTrack)->MeasureProcessCPUTime()->Unit(benchmark::kMillisecond);
BENCHMARK(BM_RecorderCameraNoTextTrackNoQueue)
    ->MeasureProcessCPUTime()
    ->Unit(benchmark::kMillisecond);
