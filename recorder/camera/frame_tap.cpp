#include "camera/frame_tap.h"

#include <gst/app/gstappsink.h>

namespace wircam::recorder {

void FrameTap::attach(GstElement* appsink) {
  detach();
  appsink_ = appsink;
  g_object_set(appsink_, "emit-signals", TRUE, nullptr);
  handler_ = g_signal_connect(appsink_, "new-sample", G_CALLBACK(onNewSample), this);
}

void FrameTap::detach() {
  if (appsink_) g_signal_handler_disconnect(appsink_, handler_);
  appsink_ = nullptr;
  handler_ = 0;
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
  {
    MutexLock lock(self->mutex_);
    gst_buffer_replace(&self->latest_, gst_sample_get_buffer(sample));
    for (auto& [id, listener] : self->listeners_) listener(sample);
  }
  gst_sample_unref(sample);
  return GST_FLOW_OK;
}

}  // namespace wircam::recorder
