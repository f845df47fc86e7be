#include "camera/segment_splitter.h"

#include <gst/video/video-event.h>

#include "camera/wall_clock.h"

namespace wircam::recorder {

namespace {

// A buffer's running time on its pad's segment; what splitmuxsink also
// measures GOPs by (decoding time when there is one).
GstClockTime runningTimeOf(const GstSegment& segment, GstBuffer* buffer) {
  return gst_segment_to_running_time(&segment, GST_FORMAT_TIME, GST_BUFFER_DTS_OR_PTS(buffer));
}

// Keeps a pad's current segment, so buffers' running times can be known.
void keepSegment(GstPadProbeInfo* info, GstSegment& segment) {
  GstEvent* event = GST_PAD_PROBE_INFO_EVENT(info);
  if (GST_EVENT_TYPE(event) == GST_EVENT_SEGMENT) gst_event_copy_segment(event, &segment);
}

}  // namespace

SegmentSplitter::SegmentSplitter(Parts parts, SegmentPlanner& planner,
                                 std::function<void()> afterFrame)
    : parts_(parts), planner_(planner), afterFrame_(std::move(afterFrame)) {
  gst_segment_init(&sourceSegment_, GST_FORMAT_TIME);
  constexpr auto kDataProbe =
      static_cast<GstPadProbeType>(GST_PAD_PROBE_TYPE_BUFFER | GST_PAD_PROBE_TYPE_EVENT_DOWNSTREAM);
  sourcePad_ = gst_element_get_static_pad(parts_.source, "src");
  sourceProbe_ = gst_pad_add_probe(sourcePad_, kDataProbe, onSourceData, this, nullptr);
  muxerPad_ = gst_element_get_static_pad(parts_.splitmux, "video");
  if (muxerPad_)
    muxerProbe_ = gst_pad_add_probe(muxerPad_, kDataProbe, onMuxerInput, this, nullptr);
  muxerAdded_ = g_signal_connect(parts_.splitmux, "muxer-added", G_CALLBACK(onMuxerAdded), this);
  sinkAdded_ = g_signal_connect(parts_.splitmux, "sink-added", G_CALLBACK(onSinkAdded), nullptr);
  formatLocation_ =
      g_signal_connect(parts_.splitmux, "format-location-full", G_CALLBACK(onFormatLocation), this);
}

SegmentSplitter::~SegmentSplitter() {
  g_signal_handler_disconnect(parts_.splitmux, muxerAdded_);
  g_signal_handler_disconnect(parts_.splitmux, sinkAdded_);
  g_signal_handler_disconnect(parts_.splitmux, formatLocation_);
  gst_pad_remove_probe(sourcePad_, sourceProbe_);
  gst_object_unref(sourcePad_);
  if (muxerPad_) {
    gst_pad_remove_probe(muxerPad_, muxerProbe_);
    gst_object_unref(muxerPad_);
  }
}

GstPadProbeReturn SegmentSplitter::onSourceData(GstPad* pad, GstPadProbeInfo* info, gpointer data) {
  auto* self = static_cast<SegmentSplitter*>(data);
  if (GST_PAD_PROBE_INFO_TYPE(info) & GST_PAD_PROBE_TYPE_EVENT_DOWNSTREAM) {
    keepSegment(info, self->sourceSegment_);
    return GST_PAD_PROBE_OK;
  }
  GstClockTime time = runningTimeOf(self->sourceSegment_, GST_PAD_PROBE_INFO_BUFFER(info));
  if (!GST_CLOCK_TIME_IS_VALID(time)) return GST_PAD_PROBE_OK;
  auto cut =
      self->planner_.onFrame(time, [self, time] { return unixMsOf(self->parts_.source, time); });
  self->afterFrame_();
  // The encoder makes this very frame a key frame (the event travels just
  // ahead of it): at a cut, and every kKeyFrameInterval, whatever the frame
  // rate, because splitmuxsink holds the newest GOP and the muxer writes
  // whole GOPs, which is what a crash loses.
  // The first frame is one anyway, and must not be asked for: x264enc
  // (GStreamer 1.22) measures that request against a segment it has not
  // set up yet, and then ignores every later one.
  if (cut == SegmentPlanner::Cut::kFirst) self->lastKeyFrame_ = time;
  bool due = time >= self->lastKeyFrame_ + kKeyFrameInterval;
  if (self->parts_.transcoded && (cut == SegmentPlanner::Cut::kNext || due)) {
    gst_pad_push_event(pad, gst_video_event_new_downstream_force_key_unit(
                                GST_BUFFER_PTS(GST_PAD_PROBE_INFO_BUFFER(info)),
                                GST_CLOCK_TIME_NONE, time, TRUE, 0));
    self->lastKeyFrame_ = time;
  }
  // splitmuxsink starts the next file at this frame.
  if (cut == SegmentPlanner::Cut::kNext)
    g_signal_emit_by_name(self->parts_.splitmux, "split-at-running-time", time);
  return GST_PAD_PROBE_OK;
}

GstPadProbeReturn SegmentSplitter::onMuxerInput(GstPad*, GstPadProbeInfo* info, gpointer data) {
  auto* self = static_cast<SegmentSplitter*>(data);
  if (GST_PAD_PROBE_INFO_TYPE(info) & GST_PAD_PROBE_TYPE_EVENT_DOWNSTREAM) {
    return GST_PAD_PROBE_OK;
  }
  self->planner_.addBytes(gst_buffer_get_size(GST_PAD_PROBE_INFO_BUFFER(info)));
  return GST_PAD_PROBE_OK;
}

void SegmentSplitter::onMuxerAdded(GstElement*, GstElement* muxer, gpointer data) {
  static_cast<SegmentSplitter*>(data)->muxer_ = muxer;
}

void SegmentSplitter::onSinkAdded(GstElement*, GstElement* sink, gpointer) {
  // filesink gathers 64 KB before it writes: minutes of a low-rate stream
  // that a crash would lose. The muxers write in pieces of a frame or more.
  if (g_object_class_find_property(G_OBJECT_GET_CLASS(sink), "buffer-mode"))
    gst_util_set_object_arg(G_OBJECT(sink), "buffer-mode", "unbuffered");
}

gchar* SegmentSplitter::onFormatLocation(GstElement*, guint, GstSample* first, gpointer data) {
  auto* self = static_cast<SegmentSplitter*>(data);
  GstBuffer* buffer = first ? gst_sample_get_buffer(first) : nullptr;
  const GstSegment* segment = first ? gst_sample_get_segment(first) : nullptr;
  if (!buffer || !segment) return nullptr;  // splitmuxsink's own location pattern then
  GstClockTime start = runningTimeOf(*segment, buffer);
  auto planned = self->planner_.segmentStartingNear(start);
  if (!planned) return nullptr;
  // The muxer writes running times: shifted by the file's start, each file
  // begins at 0. Its pads get their segments (again) after this returns.
  if (GstElement* muxer = self->muxer_.load()) {
    GstIterator* pads = gst_element_iterate_sink_pads(muxer);
    GValue item = G_VALUE_INIT;
    while (gst_iterator_next(pads, &item) == GST_ITERATOR_OK) {
      gst_pad_set_offset(GST_PAD(g_value_get_object(&item)), -static_cast<gint64>(start));
      g_value_reset(&item);
    }
    g_value_unset(&item);
    gst_iterator_free(pads);
  }
  return g_strdup(planned->path.c_str());
}

}  // namespace wircam::recorder
