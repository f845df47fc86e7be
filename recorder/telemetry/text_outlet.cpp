#include "telemetry/text_outlet.h"

#include <gst/app/gstappsrc.h>

#include <atomic>
#include <mutex>
#include <utility>

namespace wircam::recorder {

namespace {

class AppSrcOutlet : public TextOutlet {
 public:
  explicit AppSrcOutlet(GstElement* appsrc) : appsrc_(GST_APP_SRC(appsrc)) {}
  void beforeFrame(std::vector<GstBuffer*> lines, GstBuffer* gap) override {
    push(lines);
    gst_app_src_push_buffer(appsrc_, gap);
  }
  void end(std::vector<GstBuffer*> buffers) override {
    push(buffers);
    gst_app_src_end_of_stream(appsrc_);
  }
  bool allSent() const override { return gst_app_src_get_current_level_buffers(appsrc_) == 0; }

 private:
  void push(const std::vector<GstBuffer*>& buffers) {
    for (GstBuffer* buffer : buffers) gst_app_src_push_buffer(appsrc_, buffer);
  }

  GstAppSrc* appsrc_;
};

class FrameThreadOutlet : public TextOutlet {
 public:
  explicit FrameThreadOutlet(GstPad* input) : input_(GST_PAD(gst_object_ref(input))) {}
  ~FrameThreadOutlet() override {
    unrefAll(last_);
    gst_object_unref(input_);
  }

  void beforeFrame(std::vector<GstBuffer*> lines, GstBuffer* gap) override {
    if (ended_) {
      unrefAll(lines);
      gst_buffer_unref(gap);
      return;
    }
    std::call_once(started_, [&] { start(); });
    for (GstBuffer* line : lines) gst_pad_chain(input_, line);
    if (ending_) return framesEnd(gap);
    gst_pad_chain(input_, gap);
  }

  // (Called with beforeFrame and framesEnd under the track's lock.)
  void end(std::vector<GstBuffer*> buffers) override {
    last_ = std::move(buffers);
    ending_ = true;
  }

  void framesEnd() override { framesEnd(nullptr); }

  bool allSent() const override { return ended_; }

 private:
  static void unrefAll(const std::vector<GstBuffer*>& buffers) {
    for (GstBuffer* buffer : buffers) gst_buffer_unref(buffer);
  }

  // What end() was handed, then the end; in place of `gap` (the end says
  // more: nothing more at all).
  void framesEnd(GstBuffer* gap) {
    if (gap) gst_buffer_unref(gap);
    if (!ending_ || ended_) return;
    std::call_once(started_, [&] { start(); });
    for (GstBuffer* line : std::exchange(last_, {})) gst_pad_chain(input_, line);
    gst_pad_send_event(input_, gst_event_new_eos());
    ended_ = true;
  }

  // What a source's first buffer follows: its stream, caps and segment.
  void start() {
    gst_pad_send_event(input_, gst_event_new_stream_start("wircam-telemetry"));
    GstCaps* caps = gst_caps_new_simple("text/x-raw", "format", G_TYPE_STRING, "utf8", nullptr);
    gst_pad_send_event(input_, gst_event_new_caps(caps));
    gst_caps_unref(caps);
    GstSegment segment;
    gst_segment_init(&segment, GST_FORMAT_TIME);
    gst_pad_send_event(input_, gst_event_new_segment(&segment));
  }

  GstPad* input_;
  std::once_flag started_;
  std::vector<GstBuffer*> last_;  // handed to end()
  bool ending_ = false;
  std::atomic<bool> ended_{false};
};

}  // namespace

std::unique_ptr<TextOutlet> appSrcOutlet(GstElement* appsrc) {
  return std::make_unique<AppSrcOutlet>(appsrc);
}

std::unique_ptr<TextOutlet> frameThreadOutlet(GstPad* input) {
  return std::make_unique<FrameThreadOutlet>(input);
}

}  // namespace wircam::recorder
