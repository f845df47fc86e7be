#include "camera/queue_drops.h"

namespace wircam::recorder {

QueueDrops::QueueDrops(GstElement* queue) : queue_(GST_ELEMENT(gst_object_ref(queue))) {
  guint bound = 0;
  g_object_get(queue_, "max-size-bytes", &bound, nullptr);
  bound_ = bound;
  sink_ = gst_element_get_static_pad(queue_, "sink");
  probe_ = gst_pad_add_probe(sink_, GST_PAD_PROBE_TYPE_BUFFER, onFrameIn, this, nullptr);
  queryProbe_ =
      gst_pad_add_probe(sink_, GST_PAD_PROBE_TYPE_QUERY_DOWNSTREAM, onQuery, this, nullptr);
}

QueueDrops::~QueueDrops() {
  gst_pad_remove_probe(sink_, probe_);
  gst_pad_remove_probe(sink_, queryProbe_);
  gst_object_unref(sink_);
  gst_object_unref(queue_);
}

GstPadProbeReturn QueueDrops::onFrameIn(GstPad*, GstPadProbeInfo*, gpointer data) {
  auto* self = static_cast<QueueDrops*>(data);
  self->arrived_.fetch_add(1, std::memory_order_relaxed);
  // The queue would block this thread (the source's) once it holds its
  // bound; the frame goes instead. Only this thread adds to the queue, so
  // room seen here is still there when the frame goes in.
  guint level = 0;
  g_object_get(self->queue_, "current-level-bytes", &level, nullptr);
  if (self->bound_ == 0 || level < self->bound_) return GST_PAD_PROBE_OK;
  self->dropped_.fetch_add(1, std::memory_order_relaxed);
  return GST_PAD_PROBE_DROP;
}

GstPadProbeReturn QueueDrops::onQuery(GstPad*, GstPadProbeInfo* info, gpointer) {
  // A serialized query waits behind the frames queued for the disk: the
  // source's allocation query, after each file is linked (its RECONFIGURE),
  // would hold the source, and every other branch, until the queue drained.
  // Refused here: the source allocates as it would alone.
  // (GST_QUERY_IS_SERIALIZED mixes two enums, which C++20 deprecates.)
  auto type = static_cast<unsigned>(GST_QUERY_TYPE(GST_PAD_PROBE_INFO_QUERY(info)));
  if (type & static_cast<unsigned>(GST_QUERY_TYPE_SERIALIZED)) return GST_PAD_PROBE_DROP;
  return GST_PAD_PROBE_OK;
}

}  // namespace wircam::recorder
