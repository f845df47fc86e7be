// The text track beside the frames in a real matroskamux: its gaps run
// ahead of the frames, so the text's thread is not woken at every frame,
// and a line that comes behind the frames neither holds them back nor
// lands anywhere but at its own time (read back with matroskademux).
#include "telemetry/telemetry_track.h"

#include <gst/app/gstappsink.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <filesystem>
#include <future>
#include <string>
#include <vector>

namespace {

namespace fs = std::filesystem;
using wircam::recorder::TelemetryTrack;

constexpr GstClockTime kFrameInterval = GST_SECOND / 15;
constexpr int kFrames = 150;                             // 10 s
constexpr int kLineEvery = 5;                            // a line every 5th frame
constexpr GstClockTime kLineBehind = 100 * GST_MSECOND;  // a detection a frame late, or more

// appsrc → matroskamux ← a pad the test pushes frames from (as wircsrc's
// thread does) → filesink.
class TextBesideFrames {
 public:
  explicit TextBesideFrames(const fs::path& file) {
    pipeline_ = gst_parse_launch(
        ("appsrc name=text is-live=true format=time caps=text/x-raw,format=(string)utf8 "
         "! mux.subtitle_%u matroskamux name=mux ! filesink location=\"" +
         file.string() + "\"")
            .c_str(),
        nullptr);
    text_ = gst_bin_get_by_name(GST_BIN(pipeline_), "text");
    GstPad* textOut = gst_element_get_static_pad(text_, "src");
    gst_pad_add_probe(textOut, GST_PAD_PROBE_TYPE_BUFFER, onText, this, nullptr);
    gst_object_unref(textOut);
    GstElement* mux = gst_bin_get_by_name(GST_BIN(pipeline_), "mux");
    GstPad* muxVideo = gst_element_request_pad_simple(mux, "video_%u");
    frames_ = gst_pad_new("frames", GST_PAD_SRC);
    gst_pad_set_active(frames_, TRUE);
    gst_pad_link(frames_, muxVideo);
    gst_object_unref(muxVideo);
    gst_object_unref(mux);
    gst_element_set_state(pipeline_, GST_STATE_PLAYING);
    gst_pad_push_event(frames_, gst_event_new_stream_start("frames"));
    GstCaps* caps = gst_caps_from_string("image/jpeg,width=352,height=288,framerate=15/1");
    gst_pad_push_event(frames_, gst_event_new_caps(caps));
    gst_caps_unref(caps);
    GstSegment segment;
    gst_segment_init(&segment, GST_FORMAT_TIME);
    gst_pad_push_event(frames_, gst_event_new_segment(&segment));
  }
  ~TextBesideFrames() {
    gst_element_set_state(pipeline_, GST_STATE_NULL);
    gst_object_unref(frames_);
    gst_object_unref(text_);
    gst_object_unref(pipeline_);
  }

  GstElement* textSource() const { return text_; }
  // Pushes a frame as a source's thread does: returns once the muxer took it.
  GstFlowReturn pushFrame(GstClockTime pts) {
    GstBuffer* frame = gst_buffer_new_allocate(nullptr, 1000, nullptr);
    gst_buffer_memset(frame, 0, 0xAB, 1000);
    GST_BUFFER_PTS(frame) = pts;
    GST_BUFFER_DURATION(frame) = kFrameInterval;
    return gst_pad_push(frames_, frame);
  }
  void endFrames() { gst_pad_push_event(frames_, gst_event_new_eos()); }
  bool finished(GstClockTime timeout) {
    GstBus* bus = gst_element_get_bus(pipeline_);
    GstMessage* message = gst_bus_timed_pop_filtered(
        bus, timeout, static_cast<GstMessageType>(GST_MESSAGE_EOS | GST_MESSAGE_ERROR));
    bool eos = message && GST_MESSAGE_TYPE(message) == GST_MESSAGE_EOS;
    if (message) gst_message_unref(message);
    gst_object_unref(bus);
    return eos;
  }
  // Unblocks a frame held in the muxer (a failed test).
  void stop() { gst_element_set_state(pipeline_, GST_STATE_NULL); }
  int gapsSent() const { return gaps_; }

 private:
  static GstPadProbeReturn onText(GstPad* pad, GstPadProbeInfo* info, gpointer self) {
    if (!TelemetryTrack::isGap(GST_PAD_PROBE_INFO_BUFFER(info))) return GST_PAD_PROBE_OK;
    ++static_cast<TextBesideFrames*>(self)->gaps_;
    return TelemetryTrack::passGap(pad, info, true);
  }

  GstElement* pipeline_;
  GstElement* text_;
  GstPad* frames_;
  std::atomic<int> gaps_{0};
};

struct ReadBack {
  int frames = 0;
  std::vector<GstClockTime> lineTimes;
};

ReadBack readBack(const fs::path& file) {
  GstElement* pipeline = gst_parse_launch(
      ("filesrc location=\"" + file.string() +
       "\" ! matroskademux name=d d.video_0 ! queue ! appsink name=frames sync=false "
       "d.subtitle_0 ! queue ! appsink name=lines sync=false")
          .c_str(),
      nullptr);
  gst_element_set_state(pipeline, GST_STATE_PLAYING);
  ReadBack read;
  for (const char* name : {"frames", "lines"}) {
    GstElement* sink = gst_bin_get_by_name(GST_BIN(pipeline), name);
    while (GstSample* sample = gst_app_sink_try_pull_sample(GST_APP_SINK(sink), 10 * GST_SECOND)) {
      if (std::string(name) == "frames")
        ++read.frames;
      else
        read.lineTimes.push_back(GST_BUFFER_PTS(gst_sample_get_buffer(sample)));
      gst_sample_unref(sample);
      if (gst_app_sink_is_eos(GST_APP_SINK(sink))) break;
    }
    gst_object_unref(sink);
  }
  gst_element_set_state(pipeline, GST_STATE_NULL);
  gst_object_unref(pipeline);
  return read;
}

TEST(TelemetryTrack, GapsRunAheadAndALineBehindTheFramesNeitherHoldsThemNorMoves) {
  gst_init(nullptr, nullptr);
  struct RemovedAtEnd {
    fs::path path;
    ~RemovedAtEnd() { fs::remove(path); }
  } file{fs::temp_directory_path() / ("text-track-" + std::to_string(getpid()) + ".mkv")};
  std::vector<GstClockTime> written;
  int gapsSent = 0, framesPushed = 0;
  {
    TextBesideFrames pipeline(file.path);
    TelemetryTrack track(pipeline.textSource(), true);
    track.fileOpened(0);
    // The frames' thread, as wircsrc's: a line for a frame already in the
    // file, then the heartbeat, then the frame.
    auto frames = std::async(std::launch::async, [&] {
      for (int i = 0; i < kFrames; ++i) {
        GstClockTime pts = i * kFrameInterval;
        if (i > 0 && i % kLineEvery == 0) {
          written.push_back(pts - kLineBehind);
          track.write("{\"frame\":" + std::to_string(i) + "}", written.back(), 0);
        }
        track.heartbeat(pts);
        if (pipeline.pushFrame(pts) != GST_FLOW_OK) return -1;
      }
      // As SegmentWriter ends a recording: the text's lines all go to the
      // muxer first (each frame that still comes lets in one that waits
      // there for a frame), then the frames end, so that the muxer, which
      // finishes at its frames' end, has every line.
      track.end();
      int pushed = kFrames;
      for (; !track.allSent() && pushed < 2 * kFrames; ++pushed)
        if (pipeline.pushFrame(pushed * kFrameInterval) != GST_FLOW_OK) return -1;
      pipeline.endFrames();
      return pushed;
    });
    // 10 s of frames pushed as fast as the muxer takes them: a frame held
    // for a gap that never comes would hold them for ever.
    bool done = frames.wait_for(std::chrono::seconds(10)) == std::future_status::ready;
    if (!done) pipeline.stop();
    ASSERT_TRUE(done) << "a frame waited in the muxer for the text track";
    framesPushed = frames.get();
    ASSERT_GE(framesPushed, kFrames);
    ASSERT_TRUE(pipeline.finished(10 * GST_SECOND));
    gapsSent = pipeline.gapsSent();
  }
  // A gap per frame would be 150; ahead by a second, renewed at half of
  // it, 20, and one restating the promise after each of the 29 lines.
  EXPECT_LE(gapsSent, 20 + 29 + 2);
  ReadBack read = readBack(file.path);
  EXPECT_EQ(read.frames, framesPushed);
  ASSERT_EQ(read.lineTimes.size(), written.size());
  for (size_t i = 0; i < written.size(); ++i)  // Matroska keeps milliseconds
    EXPECT_NEAR(static_cast<double>(read.lineTimes[i]), static_cast<double>(written[i]),
                static_cast<double>(GST_MSECOND))
        << "line " << i;
}

}  // namespace
