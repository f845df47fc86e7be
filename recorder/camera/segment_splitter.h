// Makes one stream's splitmuxsink cut its files where the SegmentPlanner
// says, and makes every file start at timestamp 0 with a key frame:
// - a probe on the source's pad shows each frame to the planner and, at a
//   cut, asks splitmuxsink to split at that frame's time (forcing a key
//   frame there first when the stream is transcoded, as every 0.5 s);
// - a probe on splitmuxsink's video input counts bytes for the planner;
// - each new file is named by the planner, and its muxer's inputs are
//   offset by the file's start so that its timeline begins at 0.
#pragma once

#include <gst/gst.h>

#include <atomic>
#include <functional>

#include "record/segment_planner.h"

namespace wircam::recorder {

class SegmentSplitter {
 public:
  struct Parts {
    GstElement* source;    // wircsrc
    GstElement* splitmux;  // splitmuxsink
    bool transcoded;       // key frames come from an encoder that can be asked for one
  };
  // `afterFrame` runs on the source's thread once each frame is planned.
  SegmentSplitter(Parts parts, SegmentPlanner& planner, std::function<void()> afterFrame);
  ~SegmentSplitter();
  SegmentSplitter(const SegmentSplitter&) = delete;
  SegmentSplitter& operator=(const SegmentSplitter&) = delete;

 private:
  static GstPadProbeReturn onSourceData(GstPad* pad, GstPadProbeInfo* info, gpointer self);
  static GstPadProbeReturn onMuxerInput(GstPad* pad, GstPadProbeInfo* info, gpointer self);
  static void onMuxerAdded(GstElement* splitmux, GstElement* muxer, gpointer self);
  static void onSinkAdded(GstElement* splitmux, GstElement* sink, gpointer);
  static gchar* onFormatLocation(GstElement* splitmux, guint fragment, GstSample* first,
                                 gpointer self);

  Parts parts_;
  SegmentPlanner& planner_;
  std::function<void()> afterFrame_;
  GstPad* sourcePad_ = nullptr;
  GstPad* muxerPad_ = nullptr;
  gulong sourceProbe_ = 0, muxerProbe_ = 0, muxerAdded_ = 0, sinkAdded_ = 0, formatLocation_ = 0;
  static constexpr GstClockTime kKeyFrameInterval = GST_SECOND / 2;
  GstSegment sourceSegment_{};               // the source's segment, on its thread
  GstClockTime lastKeyFrame_ = 0;            // asked of the encoder, on the source's thread
  std::atomic<GstElement*> muxer_{nullptr};  // the muxer of the newest file (splitmuxsink's)
};

}  // namespace wircam::recorder
