#include "telemetry/collect_pads_turns.h"

#include <gst/base/gstaggregator.h>
#include <gst/base/gstcollectpads.h>

namespace wircam::recorder::collect_pads_turns {

namespace {

// The input's GstCollectPads bookkeeping (set as the pad's private data
// when the muxer added it), or null.
GstCollectData* collectDataOf(GstPad* input) {
  auto* data = static_cast<GstCollectData*>(gst_pad_get_element_private(input));
  return data && data->pad == input ? data : nullptr;
}

// matroskamux locks its frames' input in the waiting state (only a sparse
// input, its text, may change): unlocked for the lines, and locked again
// after them. (Marked on the pad: an input that was not locked stays so.)
GQuark unlockedForLines() {
  static GQuark quark = g_quark_from_static_string("wircam-unlocked-for-lines");
  return quark;
}

// (GST_COLLECT_PADS_STATE_SET and _UNSET, which C++ will not take.)
void setLocked(GstCollectData* data, bool locked) {
  int state = data->state;
  state = locked ? state | GST_COLLECT_PADS_STATE_LOCKED : state & ~GST_COLLECT_PADS_STATE_LOCKED;
  data->state = static_cast<GstCollectPadsStateFlags>(state);
}

void setWaiting(GstPad* input, bool waiting) {
  GstCollectData* data = collectDataOf(input);
  if (!data) return;
  GST_COLLECT_PADS_STREAM_LOCK(data->collect);
  if (!GST_COLLECT_PADS_STATE_IS_SET(data, GST_COLLECT_PADS_STATE_EOS)) {
    bool unlocked = g_object_get_qdata(G_OBJECT(input), unlockedForLines()) != nullptr;
    if (!waiting && GST_COLLECT_PADS_STATE_IS_SET(data, GST_COLLECT_PADS_STATE_LOCKED)) {
      setLocked(data, false);
      g_object_set_qdata(G_OBJECT(input), unlockedForLines(), GINT_TO_POINTER(1));
      unlocked = true;
    }
    gst_collect_pads_set_waiting(data->collect, data, waiting);
    if (waiting && unlocked) {
      setLocked(data, true);
      g_object_set_qdata(G_OBJECT(input), unlockedForLines(), nullptr);
    }
  }
  GST_COLLECT_PADS_STREAM_UNLOCK(data->collect);
}

}  // namespace

bool drive(GstPad* input) {
  GstElement* muxer = gst_pad_get_parent_element(input);
  if (!muxer) return false;
  // (An aggregator's pads keep no private data; checked first all the same.)
  bool aggregator = GST_IS_AGGREGATOR(muxer);
  gst_object_unref(muxer);
  if (aggregator) return false;
  GstCollectData* data = collectDataOf(input);
  return data && GST_IS_COLLECT_PADS(data->collect);
}

bool openForLine(GstPad* video, GstClockTime position) {
  GstCollectData* data = collectDataOf(video);
  if (!data) return false;
  if (GST_COLLECT_PADS_STATE_IS_SET(data, GST_COLLECT_PADS_STATE_EOS)) return true;
  if (!GST_CLOCK_TIME_IS_VALID(position) || !gst_pad_has_current_caps(video) ||
      data->segment.format != GST_FORMAT_TIME)
    return false;
  gst_pad_send_event(video, gst_event_new_gap(position, 1));
  setWaiting(video, false);
  return true;
}

void afterLines(GstPad* video, GstPad* text) {
  setWaiting(video, true);
  setWaiting(text, false);
}

}  // namespace wircam::recorder::collect_pads_turns
