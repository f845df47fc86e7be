#include "webrtc/camera_encoder.h"

#include <gst/app/gstappsrc.h>

#include "log_line.h"

namespace wircam::recorder {

namespace {

// Real time, no frames held back for look-ahead (lag-in-frames 0: one
// frame in, one frame out), a key frame at least every 2 s at 15 fps so a
// viewer whose request for one is lost still starts soon; browsers ask for
// one (PLI) when they join, and the tee passes that up to the encoder.
// H.264 is passed on as the recording has it; its encoder makes a key frame
// every 0.5 s (SegmentWriter), so a new viewer starts within that.
std::string description(WebRtcVideo video, unsigned kbps) {
  const std::string source =
      "appsrc name=frames is-live=true format=time do-timestamp=true leaky-type=downstream ";
  const std::string viewers = " ! tee name=viewers allow-not-linked=true";
  if (video == WebRtcVideo::kH264) return source + "max-buffers=8" + viewers;
  return source +
         "max-buffers=2 ! tjpegdec ! videoconvert ! vp8enc deadline=1 cpu-used=8 lag-in-frames=0 "
         "end-usage=cbr keyframe-max-dist=30 error-resilient=default target-bitrate=" +
         std::to_string(kbps * 1000) + viewers;
}

}  // namespace

Expected<std::unique_ptr<CameraEncoder>, std::string> CameraEncoder::start(
    FrameTap& frames, const std::string& camera, WebRtcVideo video, unsigned kbps) {
  std::unique_ptr<CameraEncoder> self(new CameraEncoder());
  self->video_ = video;
  GError* error = nullptr;
  self->pipeline_ = gst_parse_launch(description(video, kbps).c_str(), &error);
  if (!self->pipeline_) {
    std::string text = error ? error->message : "unknown error";
    g_clear_error(&error);
    return unexpected("WebRTC encoder for " + camera + ": " + text);
  }
  gst_object_set_name(GST_OBJECT(self->pipeline_), ("webrtc-" + camera).c_str());
  // Nobody reads this pipeline's bus: it is kept flushing, and errors and
  // warnings are logged on their way in.
  GstBus* bus = gst_element_get_bus(self->pipeline_);
  gst_bus_set_sync_handler(
      bus,
      [](GstBus*, GstMessage* message, gpointer name) {
        if (GST_MESSAGE_TYPE(message) == GST_MESSAGE_ERROR ||
            GST_MESSAGE_TYPE(message) == GST_MESSAGE_WARNING) {
          GError* problem = nullptr;
          if (GST_MESSAGE_TYPE(message) == GST_MESSAGE_ERROR)
            gst_message_parse_error(message, &problem, nullptr);
          else
            gst_message_parse_warning(message, &problem, nullptr);
          logLine("webrtc: " + *static_cast<std::string*>(name) + ": " +
                  GST_OBJECT_NAME(GST_MESSAGE_SRC(message)) + ": " + problem->message);
          g_error_free(problem);
        }
        return GST_BUS_PASS;
      },
      new std::string(camera), [](gpointer name) { delete static_cast<std::string*>(name); });
  gst_bus_set_flushing(bus, TRUE);
  gst_object_unref(bus);
  self->source_ = gst_bin_get_by_name(GST_BIN(self->pipeline_), "frames");
  self->tee_ = gst_bin_get_by_name(GST_BIN(self->pipeline_), "viewers");
  if (gst_element_set_state(self->pipeline_, GST_STATE_PLAYING) == GST_STATE_CHANGE_FAILURE)
    return unexpected("WebRTC encoder for " + camera + ": cannot start");
  self->frames_ = &frames;
  GstElement* source = self->source_;
  // Called on the camera's streaming thread: a push into a leaky queue of
  // two, so a slow encoder drops frames here and never holds the camera.
  self->listener_ = frames.listen([source](GstSample* sample) {
    GstCaps* caps = gst_sample_get_caps(sample);
    GstCaps* current = gst_app_src_get_caps(GST_APP_SRC(source));
    if (caps && (!current || !gst_caps_is_equal(current, caps)))
      gst_app_src_set_caps(GST_APP_SRC(source), caps);
    if (current) gst_caps_unref(current);
    // Its time is the camera pipeline's; here it gets this pipeline's
    // (do-timestamp), or webrtcbin would hold it until the other clock's
    // time came. A shallow copy: the JPEG's memory is shared.
    GstBuffer* frame = gst_buffer_copy(gst_sample_get_buffer(sample));
    GST_BUFFER_PTS(frame) = GST_BUFFER_DTS(frame) = GST_BUFFER_DURATION(frame) =
        GST_CLOCK_TIME_NONE;
    gst_app_src_push_buffer(GST_APP_SRC(source), frame);
  });
  return self;
}

CameraEncoder::~CameraEncoder() {
  // Once forget() returns, the camera's thread no longer pushes.
  if (frames_) frames_->forget(listener_);
  if (pipeline_) gst_element_set_state(pipeline_, GST_STATE_NULL);
  if (source_) gst_object_unref(source_);
  if (tee_) gst_object_unref(tee_);
  if (pipeline_) gst_object_unref(pipeline_);
}

void CameraEncoder::releaseMessages() {
  GstBus* bus = gst_element_get_bus(pipeline_);
  gst_bus_set_flushing(bus, TRUE);
  gst_object_unref(bus);
}

}  // namespace wircam::recorder
