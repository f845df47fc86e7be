// A camera in the test process, fed by an appsrc of recorded JPEG frames on
// a GstTestClock: its driver (Camera), pipeline and segment writer cut the
// files where the planner says (the segment length, a gap), each file holds
// its frames byte for byte and in order, and the supervisor hears of each
// as it closes. No device, no socket, no real time in the frames.
#include <gst/app/gstappsink.h>
#include <gst/app/gstappsrc.h>
#include <gst/check/gsttestclock.h>
#include <gst/gst.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <functional>
#include <set>
#include <thread>
#include <utility>

#include "appsrc_camera_plan.h"
#include "camera/camera.h"
#include "camera_events.h"
#include "scene_frames.h"
#include "status/camera_report.h"
#include "status/prometheus_metrics.h"

namespace {

namespace fs = std::filesystem;
using namespace wircam::recorder;
using namespace std::chrono_literals;

using Observed = wircam::testing::CameraEvents;
using wircam::testing::runMainLoopUntil;

std::string md5Of(const uint8_t* data, size_t size) {
  gchar* md5 = g_compute_checksum_for_data(G_CHECKSUM_MD5, data, size);
  std::string text = md5;
  g_free(md5);
  return text;
}

// Each video frame of a Matroska file: its bytes' MD5 and its PTS.
std::vector<std::pair<std::string, GstClockTime>> framesOf(const fs::path& file) {
  std::string description =
      "filesrc location=\"" + file.string() + "\" ! matroskademux ! appsink name=sink sync=false";
  GstElement* pipeline = gst_parse_launch(description.c_str(), nullptr);
  GstElement* sink = gst_bin_get_by_name(GST_BIN(pipeline), "sink");
  gst_element_set_state(pipeline, GST_STATE_PLAYING);
  std::vector<std::pair<std::string, GstClockTime>> frames;
  while (GstSample* sample = gst_app_sink_try_pull_sample(GST_APP_SINK(sink), 5 * GST_SECOND)) {
    GstBuffer* buffer = gst_sample_get_buffer(sample);
    GstMapInfo map;
    if (gst_buffer_map(buffer, &map, GST_MAP_READ)) {
      frames.emplace_back(md5Of(map.data, map.size), GST_BUFFER_PTS(buffer));
      gst_buffer_unmap(buffer, &map);
    }
    gst_sample_unref(sample);
  }
  gst_element_set_state(pipeline, GST_STATE_NULL);
  gst_object_unref(sink);
  gst_object_unref(pipeline);
  return frames;
}

class CameraFilesTest : public ::testing::Test {
 protected:
  void SetUp() override {
    gst_init(nullptr, nullptr);
    folder_ = fs::temp_directory_path() / ("camera-files-" + std::to_string(getpid()));
    fs::remove_all(folder_);
    fs::create_directories(folder_);
  }
  void TearDown() override {
    if (source_) gst_object_unref(source_);
    fs::remove_all(folder_);
  }

  // The recorder's plan for a camera without a device (appsrc_camera_plan.h).
  StreamPlan plan() const { return wircam::testing::appSrcCameraPlan(); }

  // Builds as the recorder does, then puts the pipeline on a test clock.
  Camera::PipelineBuilder onTestClock() {
    return [this](const StreamPlan& stream, const CameraFiles& files, FrameTap* frames,
                  FrameTap* encoded) {
      auto pipeline = CameraPipeline::build(stream, files, frames, encoded);
      if (pipeline) {
        clock_ = gst_test_clock_new();
        gst_pipeline_use_clock(GST_PIPELINE((*pipeline)->pipeline()), clock_);
        gst_object_unref(clock_);
        if (source_) gst_object_unref(source_);
        source_ = (*pipeline)->element("src");
        pipeline_ = (*pipeline)->pipeline();
        gst_object_ref(source_);
        ++builds_;
      }
      return pipeline;
    };
  }

  // Scene frame `index` at `pts`; `delta`: flagged as depending on the
  // frames before it (as H.264's between key frames).
  void push(size_t index, GstClockTime pts, bool delta = false) {
    const auto& jpeg =
        wircam::testing::sceneFrames()[index % wircam::testing::sceneFrames().size()];
    GstBuffer* buffer = gst_buffer_new_memdup(jpeg.data(), jpeg.size());
    if (delta) GST_BUFFER_FLAG_SET(buffer, GST_BUFFER_FLAG_DELTA_UNIT);
    GST_BUFFER_PTS(buffer) = GST_BUFFER_DTS(buffer) = pts;
    GST_BUFFER_DURATION(buffer) = GST_SECOND / 15;
    pushed_.push_back(md5Of(jpeg.data(), jpeg.size()));
    ASSERT_EQ(gst_app_src_push_buffer(GST_APP_SRC(source_), buffer), GST_FLOW_OK);
  }

  // Records 120 frames through a disk that stops taking data (`stall`,
  // once the first file is open) and comes back (`resume`): the live branch
  // (and detection, hence following) gets every frame, the file what fits
  // in its bound, and every frame is recorded or counted, in /api/status
  // and /metrics too.
  void expectAStalledDiskDropsAndCountsWhileTheLiveViewGoesOn(StreamPlan plan,
                                                              const std::function<void()>& stall,
                                                              const std::function<void()>& resume,
                                                              SegmentLimits limits = {});
  // The recorder's arrangement for those: a live branch beside the file's,
  // the disk's writer within 150 KB and, with the text track (the
  // recorder's default), its lines, all on the source's thread.
  StreamPlan withLiveBranch(bool textTrack) const {
    StreamPlan p = plan();
    p.description +=
        " ! tee name=t t. ! queue max-size-buffers=1000 ! appsink name=live sync=false "
        "async=false";
    p.videoTail = "t";
    p.recordBound = 150000;
    if (textTrack) wircam::testing::addTextTrack(p);
    return p;
  }

  fs::path folder_;
  GstClock* clock_ = nullptr;
  GstElement* source_ = nullptr;
  std::vector<std::string> pushed_;
  int builds_ = 0;
  GstElement* pipeline_ = nullptr;  // the camera's current one
};

TEST_F(CameraFilesTest, FilesAreCutAtTheSegmentLengthAndAtAGapAndHoldEveryFrameInOrder) {
  Observed observed;
  CameraFiles files{
      .folder = folder_.string(), .extension = ".mkv", .limits = {.maxDuration = 2 * GST_SECOND}};
  auto camera = Camera::create(plan(), files, {}, observed, onTestClock());
  ASSERT_TRUE(camera) << camera.error();
  ASSERT_TRUE((*camera)->start());
  // 6 s at 15 fps, then 1 s with no frame (a gap: > 0.5 s), then 1 s more.
  auto at = [](size_t frame) { return gst_util_uint64_scale(frame, GST_SECOND, 15); };
  for (size_t i = 0; i < 90; ++i) push(i, at(i));
  for (size_t i = 0; i < 15; ++i) push(90 + i, 7 * GST_SECOND + at(i));
  ASSERT_TRUE(runMainLoopUntil([&] { return observed.closed.size() >= 3; }, 10s))
      << observed.closed.size() << " files closed";
  (*camera)->stop();
  ASSERT_TRUE(runMainLoopUntil([&] { return observed.over; }, 10s));

  // 0-2 s, 2-4 s, 4-6 s, and the frames after the gap.
  ASSERT_EQ(observed.closed.size(), 4u);
  std::vector<uint64_t> planned;
  std::vector<std::string> recorded;
  for (const auto& [file, segment] : observed.closed) {
    planned.push_back(segment.frames);
    auto frames = framesOf(file);
    EXPECT_EQ(frames.size(), segment.frames) << file;
    ASSERT_FALSE(frames.empty()) << file;
    EXPECT_EQ(frames.front().second, 0u) << file << " starts at 0";
    for (size_t i = 1; i < frames.size(); ++i)
      EXPECT_GT(frames[i].second, frames[i - 1].second) << file;
    for (const auto& frame : frames) recorded.push_back(frame.first);
  }
  EXPECT_EQ(planned, (std::vector<uint64_t>{30, 30, 30, 15}));
  EXPECT_EQ(recorded, pushed_) << "every frame, once, in order";
  // Named by the wall-clock time of their first frame, in order.
  for (size_t i = 1; i < observed.closed.size(); ++i)
    EXPECT_LT(observed.closed[i - 1].first, observed.closed[i].first);
}

}  // namespace

namespace {

// A reload's new settings: the open file ends at its last frame, a pipeline
// with the new segment length is built at once, and its files follow it.
TEST_F(CameraFilesTest, NewSettingsEndTheFileAndTheNextPipelineRecordsWithThem) {
  Observed observed;
  CameraFiles files{.folder = folder_.string(), .extension = ".mkv", .limits = {}};
  auto camera = Camera::create(plan(), files, {}, observed, onTestClock());
  ASSERT_TRUE(camera) << camera.error();
  ASSERT_TRUE((*camera)->start());
  auto at = [](size_t frame) { return gst_util_uint64_scale(frame, GST_SECOND, 15); };
  for (size_t i = 0; i < 20; ++i) push(i, at(i));
  ASSERT_TRUE(runMainLoopUntil([&] { return (*camera)->hasFrames(); }, 5s));
  CameraFiles shorter = files;
  shorter.limits.maxDuration = GST_SECOND;
  (*camera)->replan(plan(), shorter, {});
  ASSERT_TRUE(runMainLoopUntil([&] { return builds_ == 2 && observed.closed.size() == 1; }, 5s))
      << builds_ << " builds, " << observed.closed.size() << " files closed";
  EXPECT_EQ((*camera)->report().restarts, 0u) << "new settings are not a fault";
  for (size_t i = 0; i < 30; ++i) push(20 + i, at(i));
  ASSERT_TRUE(runMainLoopUntil([&] { return observed.closed.size() >= 2; }, 5s));
  (*camera)->stop();
  ASSERT_TRUE(runMainLoopUntil([&] { return observed.over; }, 5s));
  std::vector<uint64_t> planned;
  for (const auto& [file, segment] : observed.closed) planned.push_back(segment.frames);
  EXPECT_EQ(planned, (std::vector<uint64_t>{20, 15, 15}));
}

}  // namespace

namespace {

// The file's muxer, once the first file is open.
GstElement* muxerIn(GstElement* pipeline) {
  GstElement* found = nullptr;
  GstIterator* it = gst_bin_iterate_recurse(GST_BIN(pipeline));
  GValue item = G_VALUE_INIT;
  while (!found && gst_iterator_next(it, &item) == GST_ITERATOR_OK) {
    auto* element = GST_ELEMENT(g_value_get_object(&item));
    GstElementFactory* factory = gst_element_get_factory(element);
    if (factory && std::string(GST_OBJECT_NAME(factory)) == "matroskamux")
      found = GST_ELEMENT(gst_object_ref(element));
    g_value_reset(&item);
  }
  g_value_unset(&item);
  gst_iterator_free(it);
  return found;
}

void CameraFilesTest::expectAStalledDiskDropsAndCountsWhileTheLiveViewGoesOn(
    StreamPlan p, const std::function<void()>& stall, const std::function<void()>& resume,
    SegmentLimits limits) {
  p.liveSink = "live";
  Observed observed;
  CameraFiles files{.folder = folder_.string(), .extension = ".mkv", .limits = limits};
  auto camera = Camera::create(p, files, {}, observed, onTestClock());
  ASSERT_TRUE(camera) << camera.error();
  std::atomic<int> live{0};
  (*camera)->frames()->listen([&](GstSample*) { ++live; });
  ASSERT_TRUE((*camera)->start());
  auto at = [](size_t frame) { return gst_util_uint64_scale(frame, GST_SECOND, 15); };
  push(0, at(0));
  GstElement* muxer = nullptr;
  ASSERT_TRUE(runMainLoopUntil([&] { return (muxer = muxerIn(pipeline_)) != nullptr; }, 5s));
  gst_object_unref(muxer);
  stall();
  // The disk comes back whatever fails below: a disk still stalled would
  // hold the files' end, hence the camera's teardown.
  struct Resumed {
    const std::function<void()>& resume;
    bool done = false;
    void now() {
      if (!std::exchange(done, true)) resume();
    }
    ~Resumed() { now(); }
  } resumed{resume};
  const size_t kFrames = 120;
  for (size_t i = 1; i < kFrames; ++i) {
    // (The lines go in on this thread, each just before a frame.)
    if (p.muxer.text && i % 5 == 0) (*camera)->writeTelemetry({{"frame", i}});
    push(i, at(i));
  }
  // Every frame reaches the live branch: the source never waits for the disk.
  ASSERT_TRUE(runMainLoopUntil([&] { return live.load() == static_cast<int>(kFrames); }, 5s))
      << live.load() << " of " << kFrames << " frames reached the live view";
  ASSERT_TRUE(runMainLoopUntil(
      [&] {
        (*camera)->tick();
        return (*camera)->report().recordingDropped > 0;
      },
      5s));
  // The disk comes back: what waited is written, the rest stays counted.
  resumed.now();
  (*camera)->stop();
  ASSERT_TRUE(runMainLoopUntil([&] { return observed.over; }, 10s));
  uint64_t recorded = 0;
  for (const auto& [file, segment] : observed.closed) recorded += segment.frames;
  CameraReport report = (*camera)->report();
  EXPECT_GT(report.recordingDropped, kFrames / 2) << "a 150 KB bound holds a few frames";
  EXPECT_EQ(recorded + report.recordingDropped, kFrames) << "every frame recorded or counted";
  EXPECT_EQ(statusJson(report, "")["recording_dropped"], report.recordingDropped);
  std::string metrics = prometheusText({.version = "test", .cameras = {report}});
  EXPECT_NE(metrics.find("wircam_recording_dropped_frames_total{stream=\"bench-cam0\"} " +
                         std::to_string(report.recordingDropped)),
            std::string::npos)
      << metrics;
}

// The muxer hands the bytes to the disk's writer; the disk stalls as that
// writer held. The camera's bytes wait up to their bound. Files are cut
// every 0.4 s meanwhile: a file ended on a stalled disk is closed once
// written, without holding the source. Without the text track and with it
// (its lines then go in on the source's thread too).
TEST_F(CameraFilesTest, AStalledDiskHoldsTheCamerasBoundThenDropsAndCountsWhileTheLiveViewGoesOn) {
  for (bool textTrack : {false, true}) {
    SCOPED_TRACE(textTrack ? "with the text track" : "without the text track");
    auto disk = DiskWriter::of(folder_.string());
    ASSERT_TRUE(disk) << disk.error();
    expectAStalledDiskDropsAndCountsWhileTheLiveViewGoesOn(
        withLiveBranch(textTrack), [&] { (*disk)->hold(); }, [&] { (*disk)->release(); },
        {.maxDuration = 400 * GST_MSECOND});
  }
}

// Waits until `disk` has written all it was handed so far: it writes in
// order, so a byte of a file of our own handed over now is written last.
void waitUntilWritten(wircam::recorder::DiskWriter& disk, const fs::path& folder) {
  auto marker = DiskWriter::open((folder / "marker").string());
  ASSERT_TRUE(marker);
  GstBuffer* byte = gst_buffer_new_memdup("x", 1);
  disk.write(*marker, 0, byte, std::make_shared<DiskBudget>(1));
  gst_buffer_unref(byte);
  disk.close(*marker);
  fs::remove(folder / "marker");
}

// A frame that depends on a dropped one would not decode: once the disk
// has dropped one, the frames after it are dropped too, up to the next key
// frame, even when the disk has room again.
TEST_F(CameraFilesTest, AfterADropForTheDiskTheFileResumesOnlyAtAKeyFrame) {
  StreamPlan p = plan();
  p.recordBound = 150000;
  Observed observed;
  CameraFiles files{.folder = folder_.string(), .extension = ".mkv", .limits = {}};
  auto camera = Camera::create(p, files, {}, observed, onTestClock());
  ASSERT_TRUE(camera) << camera.error();
  ASSERT_TRUE((*camera)->start());
  auto at = [](size_t frame) { return gst_util_uint64_scale(frame, GST_SECOND, 15); };
  const size_t kGop = 10, kFrames = 100;
  auto isKey = [&](size_t frame) { return frame % kGop == 0; };
  push(0, at(0));
  GstElement* muxer = nullptr;
  ASSERT_TRUE(runMainLoopUntil([&] { return (muxer = muxerIn(pipeline_)) != nullptr; }, 5s));
  gst_object_unref(muxer);
  auto disk = DiskWriter::of(folder_.string());
  ASSERT_TRUE(disk) << disk.error();
  (*disk)->hold();
  for (size_t i = 1; i <= 45; ++i) push(i, at(i), !isKey(i));
  // The held disk came back once these frames have all left the source
  // (while it was held the bound filled and the rest were dropped) and
  // what waited is written: the next frames find room.
  ASSERT_TRUE(runMainLoopUntil(
      [&] {
        guint64 waiting = 1;
        g_object_get(source_, "current-level-buffers", &waiting, nullptr);
        return waiting == 0;
      },
      5s));
  (*disk)->release();
  waitUntilWritten(**disk, folder_);
  for (size_t i = 46; i < kFrames; ++i) push(i, at(i), !isKey(i));
  (*camera)->stop();
  ASSERT_TRUE(runMainLoopUntil([&] { return observed.over; }, 10s));
  // (The drops leave a gap: the file after it is another.)
  std::set<size_t> recorded;
  for (const auto& [file, planned] : observed.closed)
    for (const auto& [md5, pts] : framesOf(file))
      recorded.insert(
          static_cast<size_t>(gst_util_uint64_scale_round(planned.start + pts, 15, GST_SECOND)));
  EXPECT_GT((*camera)->report().recordingDropped, 0u);
  EXPECT_EQ(recorded.size() + (*camera)->report().recordingDropped, kFrames);
  size_t resumed = 0;
  for (size_t frame : recorded) {
    if (frame > 0 && !recorded.count(frame - 1)) {
      ++resumed;
      EXPECT_TRUE(isKey(frame)) << "frame " << frame << " follows a dropped one";
    }
  }
  EXPECT_GT(resumed, 0u) << "the file went on after the drops";
  EXPECT_FALSE(recorded.count(46)) << "a delta frame after the disk came back";
  EXPECT_TRUE(recorded.count(50)) << "the next key frame";
}

}  // namespace
