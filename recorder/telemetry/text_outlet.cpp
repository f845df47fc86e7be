#include "telemetry/text_outlet.h"

#include <gst/app/gstappsrc.h>

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

}  // namespace

std::unique_ptr<TextOutlet> appSrcOutlet(GstElement* appsrc) {
  return std::make_unique<AppSrcOutlet>(appsrc);
}

}  // namespace wircam::recorder
