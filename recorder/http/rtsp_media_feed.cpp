#include "http/rtsp_media_feed.h"

#include <gst/app/gstappsrc.h>

namespace wircam::recorder {

namespace {

// A source takes frames only once it is PLAYING. It stamps a frame with its
// clock's time less its base time, and while its pipeline goes to PLAYING
// it has the clock before the base time: a frame taken in between is
// stamped with the clock's whole time (the machine's uptime), and the RTP
// sink, which syncs, holds it and all behind it that long: the client gets
// nothing. (Nor would frames kept while PAUSED help: stamped on the old base
// time, they would be early for the new one.)
bool isPlaying(GstElement* source) {
  GST_OBJECT_LOCK(source);
  bool playing = GST_STATE(source) == GST_STATE_PLAYING;
  GST_OBJECT_UNLOCK(source);
  return playing;
}

}  // namespace

RtspMediaFeed::~RtspMediaFeed() {
  MutexLock lock(mutex_);
  for (GstElement* source : sources_) gst_object_unref(source);
}

void RtspMediaFeed::add(GstElement* source) {
  MutexLock lock(mutex_);
  sources_.push_back(GST_ELEMENT(gst_object_ref(source)));
}

void RtspMediaFeed::removeWithin(GstElement* bin) {
  MutexLock lock(mutex_);
  for (auto it = sources_.begin(); it != sources_.end();) {
    if (gst_object_has_as_ancestor(GST_OBJECT(*it), GST_OBJECT(bin))) {
      gst_object_unref(*it);
      it = sources_.erase(it);
    } else {
      ++it;
    }
  }
}

void RtspMediaFeed::push(GstSample* sample) {
  MutexLock lock(mutex_);
  if (sources_.empty()) return;
  // Same memory, fresh metadata: the appsrc stamps it. The caps carry the
  // frame size, which rtpjpegpay needs.
  GstBuffer* jpeg =
      gst_buffer_copy_region(gst_sample_get_buffer(sample), GST_BUFFER_COPY_MEMORY, 0, -1);
  GstSample* fresh = gst_sample_new(jpeg, gst_sample_get_caps(sample), nullptr, nullptr);
  gst_buffer_unref(jpeg);
  for (GstElement* source : sources_)
    if (isPlaying(source)) gst_app_src_push_sample(GST_APP_SRC(source), fresh);
  gst_sample_unref(fresh);
}

void RtspMediaFeed::end() {
  MutexLock lock(mutex_);
  for (GstElement* source : sources_) gst_app_src_end_of_stream(GST_APP_SRC(source));
}

}  // namespace wircam::recorder
