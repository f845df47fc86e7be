// One recorded file in a camera's pipeline: a muxer of GStreamer's own and a
// sink (the filesystem's DiskWriter's, or a filesink), added while the
// pipeline plays and removed once the file is finished. Its inputs are
// shifted by the file's first frame's running time, so that its timeline
// begins at 0.
//
// Once the file is written (the muxer has finished it and its bytes are
// on the disk) the sink posts an element message named kClosedMessage with
// the file's "location"; the camera then takes the file out of the
// pipeline on the main loop.
#pragma once

#include <gst/gst.h>

#include <atomic>
#include <cstdint>
#include <memory>
#include <string>

#include "camera/disk_writer.h"
#include "camera/pipeline_plan.h"
#include "common/expected.h"

namespace wircam::recorder {

class SegmentFile {
 public:
  static constexpr const char* kOpenedMessage = "wircam-file-opened";
  static constexpr const char* kClosedMessage = "wircam-file-closed";

  // In `pipeline`, playing, writing `path` to `disk`; posts
  // kOpenedMessage. `number` is the file's (TelemetryTrack::fileOpened's).
  static Expected<std::unique_ptr<SegmentFile>, std::string> open(
      GstElement* pipeline, const MuxerSpec& muxer, const CameraDisk& disk, const std::string& path,
      GstClockTime start, uint64_t number);
  // Out of the pipeline (NULL first). Not on a thread that streams into it.
  ~SegmentFile();
  SegmentFile(const SegmentFile&) = delete;
  SegmentFile& operator=(const SegmentFile&) = delete;

  const std::string& path() const { return path_; }
  GstClockTime start() const { return start_; }
  uint64_t number() const { return number_; }
  GstPad* videoInput() const { return videoInput_; }
  GstPad* textInput() const { return textInput_; }

  // The frames' and the lines' turns on the one thread that feeds both
  // inputs (telemetry/collect_pads_turns.h; nothing for a muxer that does not
  // make one input wait for the other). A line at `position` of the
  // frames' segment: true once it may go in, false if it cannot now.
  bool letLineIn(GstClockTime position);
  bool takesTurns() const { return takesTurns_; }
  // After the lines (nothing if none went in since the last call).
  void afterLines();

  // The end of its frames, or of its text (EOS into that input, once).
  void endVideo() {
    linesOpen_ = false;  // (its EOS ends what the lines' turn changed)
    end(videoInput_, videoEnded_);
  }
  // The same at the run's end: the file is on the disk before its sink
  // says it has ended (a cut mid-run does not wait for a slow disk).
  void endVideoAtTheRunsEnd();
  void endText() {
    afterLines();
    end(textInput_, textEnded_);
  }
  // The muxer has finished the file (its EOS reached the filesink): an
  // input fed now would answer EOS, which stops the thread feeding it.
  bool closed() const { return closed_; }

 private:
  SegmentFile() = default;
  static void end(GstPad* input, std::atomic<bool>& ended);
  static GstPadProbeReturn onSinkEvent(GstPad* pad, GstPadProbeInfo* info, gpointer self);
  // kClosedMessage from `sink`, for the file at `path`.
  static void postClosed(GstElement* sink, const std::string& path);
  // The sink for `path`, or an error.
  Expected<GstElement*, std::string> makeSink(const CameraDisk& disk);

  GstElement* pipeline_ = nullptr;  // borrowed
  GstElement* muxer_ = nullptr;     // owned by the pipeline while in it
  GstElement* sink_ = nullptr;
  GstPad* videoInput_ = nullptr;  // the muxer's request pads (ours)
  GstPad* textInput_ = nullptr;
  std::string path_;
  GstClockTime start_ = 0;
  uint64_t number_ = 0;
  std::atomic<bool> videoEnded_{false}, textEnded_{false}, closed_{false};
  bool writtenBySink_ = false;  // a filesink: on the disk as the muxer ends
  bool takesTurns_ = false;     // its muxer's inputs wait for each other
  bool linesOpen_ = false;      // its frames' input is not waited for, for lines
};

}  // namespace wircam::recorder
