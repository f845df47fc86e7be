// The text track beside the frames in a real matroskamux, all from the
// frames' own thread as the recorder feeds it: a frame lets in the lines
// due up to it, each given its turn in the muxer (collect_pads_turns.h),
// and then its gap (none while the gap before reaches past it); nothing
// waits, no other thread takes part, and a line that comes behind the
// frames neither holds them back nor lands anywhere but at its own time
// (read back with matroskademux).
#include "telemetry/telemetry_track.h"

#include <gst/app/gstappsink.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <filesystem>
#include <future>
#include <string>
#include <thread>
#include <vector>

#include "telemetry/collect_pads_turns.h"

namespace {

namespace fs = std::filesystem;
using wircam::recorder::TelemetryTrack;
namespace turns = wircam::recorder::collect_pads_turns;

constexpr GstClockTime kFrameInterval = GST_SECOND / 15;
constexpr int kFrames = 150;                             // 10 s
constexpr int kLineEvery = 5;                            // a line every 5th frame,
constexpr int kLinesUntil = 75;                          // for the first 5 s
constexpr GstClockTime kLineBehind = 100 * GST_MSECOND;  // a detection a frame late, or more

// taginject (the recorder's text tail) → matroskamux ← a pad the test
// pushes frames from (as wircsrc's thread does) → filesink. A probe where
// the text leaves gives each line its turn and passes the gaps, as the
// recorder's SegmentWriter does.
class TextBesideFrames {
 public:
  explicit TextBesideFrames(const fs::path& file) {
    pipeline_ = gst_parse_launch(
        ("taginject name=text ! mux.subtitle_%u matroskamux name=mux ! filesink location=\"" +
         file.string() + "\"")
            .c_str(),
        nullptr);
    text_ = gst_bin_get_by_name(GST_BIN(pipeline_), "text");
    GstPad* textOut = gst_element_get_static_pad(text_, "src");
    gst_pad_add_probe(textOut, GST_PAD_PROBE_TYPE_BUFFER, onText, this, nullptr);
    muxText_ = gst_pad_get_peer(textOut);
    gst_object_unref(textOut);
    GstElement* mux = gst_bin_get_by_name(GST_BIN(pipeline_), "mux");
    muxVideo_ = gst_element_request_pad_simple(mux, "video_%u");
    frames_ = gst_pad_new("frames", GST_PAD_SRC);
    gst_pad_set_active(frames_, TRUE);
    gst_pad_link(frames_, muxVideo_);
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
    gst_object_unref(muxVideo_);
    gst_object_unref(muxText_);
    gst_object_unref(text_);
    gst_object_unref(pipeline_);
  }

  // The text's way in, as the recorder feeds it.
  std::unique_ptr<wircam::recorder::TextOutlet> textOutlet() const {
    GstPad* input = gst_element_get_static_pad(text_, "sink");
    auto outlet = wircam::recorder::frameThreadOutlet(input);
    gst_object_unref(input);
    return outlet;
  }
  void setFramesThread(std::thread::id id) { framesThread_ = id; }
  GstPad* muxerVideoInput() const { return muxVideo_; }
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
  // Buffers that went to the muxer on the frames' own thread: lines, gaps.
  int linesFromFramesThread() const { return framesThreadLines_; }
  int gapsFromFramesThread() const { return framesThreadGaps_; }

 private:
  static GstPadProbeReturn onText(GstPad* pad, GstPadProbeInfo* info, gpointer data) {
    auto* self = static_cast<TextBesideFrames*>(data);
    bool onFramesThread = std::this_thread::get_id() == self->framesThread_;
    GstBuffer* buffer = GST_PAD_PROBE_INFO_BUFFER(info);
    if (!TelemetryTrack::isGap(buffer)) {
      if (onFramesThread) ++self->framesThreadLines_;
      // (The frames' segment starts at 0: a running time is its position.)
      return turns::openForLine(self->muxVideo_, GST_BUFFER_PTS(buffer)) ? GST_PAD_PROBE_OK
                                                                         : GST_PAD_PROBE_DROP;
    }
    ++self->gaps_;
    if (onFramesThread) ++self->framesThreadGaps_;
    GstPadProbeReturn answer = TelemetryTrack::passGap(pad, info, true);
    turns::afterLines(self->muxVideo_, self->muxText_);
    return answer;
  }

  GstElement* pipeline_;
  GstElement* text_;
  GstPad* frames_;
  GstPad* muxVideo_;  // the muxer's inputs
  GstPad* muxText_;
  std::atomic<int> gaps_{0}, framesThreadLines_{0}, framesThreadGaps_{0};
  std::thread::id framesThread_;
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

TEST(TelemetryTrack, AFrameLetsInTheLinesUpToItAllOnItsOwnThread) {
  gst_init(nullptr, nullptr);
  struct RemovedAtEnd {
    fs::path path;
    ~RemovedAtEnd() { fs::remove(path); }
  } file{fs::temp_directory_path() / ("text-track-" + std::to_string(getpid()) + ".mkv")};
  std::vector<GstClockTime> written;
  int framesPushed = 0;
  {
    TextBesideFrames pipeline(file.path);
    TelemetryTrack track(pipeline.textOutlet(), false);
    track.fileOpened(0);
    EXPECT_TRUE(turns::drive(pipeline.muxerVideoInput()));
    // The frames' thread, as wircsrc's: a line for a frame already in the
    // file, then the frame, which lets in what is due before it.
    auto frames = std::async(std::launch::async, [&] {
      pipeline.setFramesThread(std::this_thread::get_id());
      for (int i = 0; i < kFrames; ++i) {
        GstClockTime pts = i * kFrameInterval;
        if (i > 0 && i < kLinesUntil && i % kLineEvery == 0) {
          written.push_back(pts - kLineBehind);
          track.write("{\"frame\":" + std::to_string(i) + "}", written.back(), 0);
        }
        track.beforeFrame(pts, 1);
        if (pipeline.pushFrame(pts) != GST_FLOW_OK) return -1;
      }
      // As SegmentWriter ends a recording: a line no frame reached, then
      // the text's end, which goes in at the frames' end.
      written.push_back(kFrames * kFrameInterval);
      track.write("{\"last\":true}", written.back(), 0);
      track.end();
      EXPECT_FALSE(track.allSent());
      track.framesEnd();
      EXPECT_TRUE(track.allSent());
      pipeline.endFrames();
      return kFrames;
    });
    // 10 s of frames pushed as fast as the muxer takes them: a frame or a
    // line held for the other would hold them for ever.
    bool done = frames.wait_for(std::chrono::seconds(10)) == std::future_status::ready;
    if (!done) pipeline.stop();
    ASSERT_TRUE(done) << "a frame or a line waited in the muxer";
    framesPushed = frames.get();
    ASSERT_EQ(framesPushed, kFrames);
    ASSERT_TRUE(pipeline.finished(10 * GST_SECOND));
    // Every line and every gap went in on the frames' thread.
    EXPECT_EQ(pipeline.linesFromFramesThread(), static_cast<int>(written.size()));
    // A gap at the first frame and after each line; then, in the 5 s
    // without lines, one a second (each reaches a second past its frame).
    EXPECT_EQ(pipeline.gapsFromFramesThread(), pipeline.gapsSent());
    int linesAmongFrames = static_cast<int>(written.size()) - 1;  // the last came after them
    EXPECT_GE(pipeline.gapsSent(), 1 + linesAmongFrames + 4);
    EXPECT_LE(pipeline.gapsSent(), 1 + linesAmongFrames + 5);
  }
  ReadBack read = readBack(file.path);
  EXPECT_EQ(read.frames, framesPushed);
  // (The last line, past the last frame, is at its own time too.)
  ASSERT_EQ(read.lineTimes.size(), written.size());
  for (size_t i = 0; i < written.size(); ++i)  // Matroska keeps milliseconds
    EXPECT_NEAR(static_cast<double>(read.lineTimes[i]), static_cast<double>(written[i]),
                static_cast<double>(GST_MSECOND))
        << "line " << i;
}

// mp4mux writes a text track's samples end to end: lines of one moment,
// and a gap just after a line, each last kLineDuration and must not
// overlap (they did, and the file's text track had a negative duration,
// which ffprobe read as 4,294,967 s). What the track hands its outlet:
class Kept : public wircam::recorder::TextOutlet {
 public:
  explicit Kept(std::vector<GstBuffer*>& kept) : kept_(kept) {}
  void beforeFrame(std::vector<GstBuffer*> lines, GstBuffer* gap) override {
    kept_.insert(kept_.end(), lines.begin(), lines.end());
    kept_.push_back(gap);
  }
  void end(std::vector<GstBuffer*> lines) override {
    kept_.insert(kept_.end(), lines.begin(), lines.end());
  }
  bool allSent() const override { return true; }

 private:
  std::vector<GstBuffer*>& kept_;
};

TEST(TelemetryTrack, AsSamplesEachStartsWhereTheOneBeforeEnds) {
  gst_init(nullptr, nullptr);
  std::vector<GstBuffer*> kept;
  {
    TelemetryTrack track(std::make_unique<Kept>(kept), true);
    track.fileOpened(0);
    track.write("{\"event\":\"live\"}", 0, 0);
    track.write("{\"event\":\"control\"}", 0, 0);
    track.beforeFrame(0, 1);
    track.write("{\"late\":true}", 0, 0);  // after the gap, of a moment before it
    track.beforeFrame(kFrameInterval, 1);
    track.end();
  }
  ASSERT_EQ(kept.size(), 5u);  // two lines, a gap, a line, a gap
  for (size_t i = 1; i < kept.size(); ++i)
    EXPECT_GE(GST_BUFFER_PTS(kept[i]),
              GST_BUFFER_PTS(kept[i - 1]) + GST_BUFFER_DURATION(kept[i - 1]))
        << "sample " << i;
  EXPECT_LE(GST_BUFFER_PTS(kept[4]), kFrameInterval + 1);  // the gap still just after its frame
  for (GstBuffer* buffer : kept) gst_buffer_unref(buffer);
}

}  // namespace
