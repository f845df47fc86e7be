#include "camera/frame_tap.h"

#include <gst/app/gstappsink.h>

#include "camera/wall_clock.h"

namespace wircam::recorder {

void FrameTap::attach(GstElement* appsink) {
  detach();
  appsink_ = appsink;
  g_object_set(appsink_, "emit-signals", TRUE, nullptr);
  handler_ = g_signal_connect(appsink_, "new-sample", G_CALLBACK(onNewSample), this);
}

void FrameTap::attachPad(GstPad* pad) {
  detach();
  pad_ = GST_PAD(gst_object_ref(pad));
  probe_ = gst_pad_add_probe(
      pad_, GST_PAD_PROBE_TYPE_BUFFER,
      [](GstPad* tapped, GstPadProbeInfo* info, gpointer self) {
        auto* tap = static_cast<FrameTap*>(self);
        GstCaps* caps = gst_pad_get_current_caps(tapped);
        // The segment too, so that the frame's running time can be known.
        GstEvent* event = gst_pad_get_sticky_event(tapped, GST_EVENT_SEGMENT, 0);
        const GstSegment* segment = nullptr;
        if (event) gst_event_parse_segment(event, &segment);
        GstSample* sample = gst_sample_new(GST_PAD_PROBE_INFO_BUFFER(info), caps, segment, nullptr);
        if (event) gst_event_unref(event);
        if (caps) gst_caps_unref(caps);
        tap->hand(sample);
        gst_sample_unref(sample);
        return GST_PAD_PROBE_OK;
      },
      this, nullptr);
}

void FrameTap::detach() {
  if (appsink_) g_signal_handler_disconnect(appsink_, handler_);
  appsink_ = nullptr;
  handler_ = 0;
  if (pad_) {
    gst_pad_remove_probe(pad_, probe_);
    gst_object_unref(pad_);
  }
  pad_ = nullptr;
  probe_ = 0;
}

FrameTap::~FrameTap() {
  detach();
  MutexLock lock(mutex_);
  gst_buffer_replace(&latest_, nullptr);
}

GstBuffer* FrameTap::latest() {
  MutexLock lock(mutex_);
  return latest_ ? gst_buffer_ref(latest_) : nullptr;
}

int FrameTap::listen(Listener listener) {
  MutexLock lock(mutex_);
  listeners_[nextId_] = std::move(listener);
  return nextId_++;
}

void FrameTap::forget(int id) {
  MutexLock lock(mutex_);
  listeners_.erase(id);
}

GstFlowReturn FrameTap::onNewSample(GstElement* appsink, gpointer data) {
  auto* self = static_cast<FrameTap*>(data);
  GstSample* sample = gst_app_sink_pull_sample(GST_APP_SINK(appsink));
  if (!sample) return GST_FLOW_EOS;
  self->hand(sample);
  gst_sample_unref(sample);
  return GST_FLOW_OK;
}

int64_t FrameTap::wallTimeNs(GstSample* sample) const {
  GstElement* element = appsink_ ? appsink_ : pad_ ? GST_PAD_PARENT(pad_) : nullptr;
  GstBuffer* buffer = gst_sample_get_buffer(sample);
  const GstSegment* segment = gst_sample_get_segment(sample);
  GstClockTime running = GST_CLOCK_TIME_NONE;
  if (buffer && segment && segment->format == GST_FORMAT_TIME)
    running = gst_segment_to_running_time(segment, GST_FORMAT_TIME, GST_BUFFER_PTS(buffer));
  if (!element) return g_get_real_time() * 1000;
  return unixNsOf(element, running);
}

void FrameTap::hand(GstSample* sample) {
  MutexLock lock(mutex_);
  gst_buffer_replace(&latest_, gst_sample_get_buffer(sample));
  for (auto& [id, listener] : listeners_) listener(sample);
}

}  // namespace wircam::recorder
