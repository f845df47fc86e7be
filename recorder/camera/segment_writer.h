// Writes one stream's frames and telemetry into the files the
// SegmentPlanner plans, each file a muxer and a sink of its own
// (SegmentFile), with no queue and no thread of its own:
// - a probe where the frames enter the recording (the encoder, or where
//   they leave for the file) drops each frame its disk has no room for
//   (CameraDisk's budget) and shows the others to the planner;
//   at a cut it opens the next file there and then (forcing a key frame
//   first when the stream is transcoded, as every 0.5 s);
// - a probe where the frames leave for the file moves them to the newest
//   file at its first frame, ending the one before (EOS), counts bytes,
//   and lets the text track's lines up to the frame go first
//   (TelemetryTrack::beforeFrame);
// - a probe where the telemetry leaves for the file does the same for the
//   text, by the file number each buffer carries, on the thread that
//   pushes it: the frames' own for Matroska, which gives the lines their
//   turns in the muxer (SegmentFile::letLineIn).
// A file is finished once both its inputs have ended; the camera then
// takes it out of the pipeline (finished()).
#pragma once

#include <gst/gst.h>

#include <chrono>
#include <deque>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "camera/pipeline_plan.h"
#include "camera/segment_file.h"
#include "common/mutex.h"
#include "record/segment_planner.h"
#include "telemetry/telemetry_track.h"

namespace wircam::recorder {

class SegmentWriter {
 public:
  struct Parts {
    GstElement* pipeline;
    GstElement* source;  // wircsrc: its end ends the recording
    // Frames are planned (or dropped for the disk) as they enter it: the
    // encoder, so that a dropped frame is never encoded; null: as they
    // leave videoTail.
    GstElement* planPoint;
    GstElement* videoTail;  // frames leave it for the file (a tee: by a pad of their own)
    GstElement* textTail;   // the telemetry leaves it for the file (null: no text track)
    MuxerSpec muxer;
    CameraDisk disk;
    bool transcoded;  // key frames come from an encoder that can be asked for one
  };
  // `afterFrame` runs on the source's thread once each frame is planned.
  SegmentWriter(Parts parts, SegmentPlanner& planner, TelemetryTrack& track,
                std::function<void()> afterFrame);
  ~SegmentWriter();
  SegmentWriter(const SegmentWriter&) = delete;
  SegmentWriter& operator=(const SegmentWriter&) = delete;

  // The end of the recording: the text track ends after its lines, then
  // the source's frames (EOS); each open file is finished. On the main
  // loop, once.
  void end();
  // A file is finished (its SegmentFile::kClosedMessage), and, with
  // `release`, out of the pipeline. (Not while the run ends: the filesink
  // has yet to tell the pipeline its EOS.) On the main loop.
  void finished(const std::string& path, bool release);
  // The files not finished yet (a run cut off indexes them as they are).
  std::vector<std::string> unfinished() const;

 private:
  static GstPadProbeReturn onSourceData(GstPad* pad, GstPadProbeInfo* info, gpointer self);
  static GstPadProbeReturn onVideoOut(GstPad* pad, GstPadProbeInfo* info, gpointer self);
  static GstPadProbeReturn onSourceDataAndVideoOut(GstPad* pad, GstPadProbeInfo* info,
                                                   gpointer self);
  static GstPadProbeReturn onTextOut(GstPad* pad, GstPadProbeInfo* info, gpointer self);
  // False: the frame is dropped (its disk is behind).
  bool planFrame(GstPad* pad, GstPadProbeInfo* info);
  // The frame's disk has no room for it, or a frame before it that it
  // depends on was dropped; counted.
  bool noRoomFor(GstBuffer* frame);
  GstPadProbeReturn routeFrame(GstPad* pad, GstPadProbeInfo* info);
  GstPadProbeReturn routeText(GstPad* pad, GstPadProbeInfo* info);
  // The text goes to file `number` from now on; false: it has no file.
  bool moveText(GstPad* pad, uint64_t number);
  // The text's file takes `line` now (SegmentFile::letLineIn); false: the
  // line cannot go in, and stays in the sidecar only.
  bool letLineIn(GstBuffer* line);
  void open(GstClockTime start);
  // The file `planned` starting at `start` joins the pipeline; false: it
  // would not open.
  bool addFile(const PlannedSegment& planned, GstClockTime start) WIRCAM_REQUIRES(mutex_);
  // EOS from the source (after the text's lines, or kTextDrain after end()).
  void endFrames();
  static gboolean onTextDrainTick(gpointer self);

  Parts parts_;
  SegmentPlanner& planner_;
  TelemetryTrack& track_;
  std::function<void()> afterFrame_;
  GstPad* sourcePad_ = nullptr;
  GstPad* videoPad_ = nullptr;  // ours when requested from a tee
  bool videoPadRequested_ = false;
  GstPad* textPad_ = nullptr;
  gulong sourceProbe_ = 0, videoProbe_ = 0, textProbe_ = 0;

  static constexpr GstClockTime kKeyFrameInterval = GST_SECOND / 2;
  // How long the frames wait at the end for the text's lines to go first.
  static constexpr std::chrono::milliseconds kTextDrain{300};
  guint textDrain_ = 0;  // the wait's ticks, on the main loop
  std::chrono::steady_clock::time_point textDrainEnds_;
  GstSegment sourceSegment_{};     // the source's segment, on its thread
  GstSegment videoSegment_{};      // the frames' segment where they leave, on that thread
  GstClockTime lastKeyFrame_ = 0;  // asked of the encoder, on the source's thread
  bool dropping_ = false;          // until a key frame, on the source's thread

  mutable Mutex mutex_;
  std::deque<std::unique_ptr<SegmentFile>> files_ WIRCAM_GUARDED_BY(mutex_);  // oldest first
  std::vector<std::string> finished_ WIRCAM_GUARDED_BY(mutex_);  // of those still in files_
  uint64_t opened_ WIRCAM_GUARDED_BY(mutex_) = 0;
  bool broken_ WIRCAM_GUARDED_BY(mutex_) = false;     // a file would not open: frames are dropped
  bool textEnded_ WIRCAM_GUARDED_BY(mutex_) = false;  // the text track has ended (a stop)
  SegmentFile* video_ WIRCAM_GUARDED_BY(mutex_) = nullptr;  // the file the frames go to
  SegmentFile* text_ WIRCAM_GUARDED_BY(mutex_) = nullptr;   // the file the text goes to
};

}  // namespace wircam::recorder
