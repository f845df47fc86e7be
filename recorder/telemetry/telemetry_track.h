// The telemetry as a timed text track inside the recording: each JSON line
// becomes one UTF-8 text buffer at the running time it belongs to, tagged
// with the file it is for.
//
// Files are numbered as they open (1, 2, ...); a buffer's offset
// (GST_BUFFER_OFFSET) is its file's number, which is how the SegmentWriter
// knows when the text moves on to the next file.
//
// A line waits here until a frame after its file's first, at or after its
// time, is about to enter its file (beforeFrame): a muxer hands on a frame
// only once every track has passed its time, so the line goes in then, and
// after it a gap (the text has nothing more up to the frame) that lets the
// frame through. For matroskamux the gap reaches a second past the frame,
// so the frames after it that no line precedes go in without one: with a
// gap a frame the text track cost 3.7 µs a frame, now 1.2 µs
// (bench_recorder_camera, docs/performance.md). A line may still come
// within that second; its muxer takes it all the same.
#pragma once

#include <gst/gst.h>

#include <cstdint>
#include <deque>
#include <memory>
#include <string>
#include <vector>

#include "common/mutex.h"
#include "telemetry/text_outlet.h"

namespace wircam::recorder {

class TelemetryTrack {
 public:
  // `outlet`: where the files' text track goes; null: the files have none,
  // and every line is refused. `gapsAreSamples`: the muxer writes gaps as
  // empty samples (mp4mux), whose times must rise, and lines' after them;
  // matroskamux takes them as GAP events (passGap) and writes nothing.
  TelemetryTrack(std::unique_ptr<TextOutlet> outlet, bool gapsAreSamples)
      : outlet_(std::move(outlet)), gapsAreSamples_(gapsAreSamples) {}

  // A line for the file that starts at running time `fileStart`. A muxer
  // wants the timestamps of a track to rise, but events arrive a little out
  // of order (a detection is stamped with its frame's time, a little after
  // later statistics): such a line is placed at the latest time already
  // written; its own "pts" field keeps the exact time.
  // A line for a file not open yet waits for it; one for a file the track
  // has moved past is refused (false): it stays in the sidecar only.
  bool write(const std::string& json, GstClockTime pts, GstClockTime fileStart);

  // A file starting at `start` opened: the lines that waited for it wait
  // now for its frames. Returns its number.
  uint64_t fileOpened(GstClockTime start);

  // A frame at `frameTime` is about to enter file `file`, on its thread:
  // the lines it reaches go to the outlet, then a gap just past it (none
  // when there is no line and the gap before reaches past the frame).
  void beforeFrame(GstClockTime frameTime, uint64_t file);

  static bool isGap(GstBuffer* buffer) {
    return GST_BUFFER_FLAG_IS_SET(buffer, GST_BUFFER_FLAG_GAP) && gst_buffer_get_size(buffer) == 0;
  }
  // A probe's answer to a gap (isGap) on its way out of `pad` to a muxer:
  // as a GAP event, for which matroskamux writes nothing, not even to the
  // file's duration (`asEvent`); or as a plain empty buffer, for mp4mux
  // (an aggregator, GStreamer 1.22), which stalls on GAP events.
  static GstPadProbeReturn passGap(GstPad* pad, GstPadProbeInfo* info, bool asEvent);

  // No more lines: the text track ends after the ones waiting, with the
  // next frame or at the frames' end.
  void end();
  // The frames end, on their thread: what end() left goes in now.
  void framesEnd();
  // Every line has gone on to the muxer.
  bool allSent() const;

  static uint64_t fileOf(GstBuffer* buffer) { return GST_BUFFER_OFFSET(buffer); }

 private:
  struct Line {
    std::string json;
    GstClockTime pts;
    uint64_t file;
  };
  // The line as the buffer its file's track goes on with.
  GstBuffer* stamp(const Line& line) WIRCAM_REQUIRES(mutex_);
  // A sample's start at `pts` or after the one before's end (mp4mux
  // writes samples end to end: two lines of one moment, each lasting
  // kLineDuration, overlapped, and the file's text track got a negative
  // duration).
  GstClockTime startAfterTheLast(GstClockTime pts) WIRCAM_REQUIRES(mutex_);
  // Buffers for `file` from now on: its times rise on their own.
  void moveTo(uint64_t file) WIRCAM_REQUIRES(mutex_);
  static GstBuffer* bufferOf(GstBuffer* buffer, GstClockTime pts, GstClockTime duration,
                             uint64_t file);

  struct Waiting {
    std::string json;
    GstClockTime pts, fileStart;
  };

  const std::unique_ptr<TextOutlet> outlet_;
  const bool gapsAreSamples_;
  // Lines come from the main loop, frames and openings from streaming; the
  // outlet is fed under it, so that what it is handed stays in order.
  mutable Mutex mutex_;
  uint64_t openFile_ WIRCAM_GUARDED_BY(mutex_) = 0;       // the newest file's number (0: none)
  GstClockTime openStart_ WIRCAM_GUARDED_BY(mutex_) = 0;  // and its start
  GstClockTime previousStart_ WIRCAM_GUARDED_BY(mutex_) = GST_CLOCK_TIME_NONE;  // the one before's
  uint64_t sentFile_ WIRCAM_GUARDED_BY(mutex_) = 0;  // the file of the newest buffer sent
  // The newest line's time in it (samples: the end of the newest).
  GstClockTime last_ WIRCAM_GUARDED_BY(mutex_) = 0;
  bool ended_ WIRCAM_GUARDED_BY(mutex_) = false;
  // Where the newest gap (matroskamux's) left the text, and in which file.
  uint64_t gapFile_ WIRCAM_GUARDED_BY(mutex_) = 0;
  GstClockTime gapEnd_ WIRCAM_GUARDED_BY(mutex_) = 0;
  uint64_t framesFile_ WIRCAM_GUARDED_BY(mutex_) = 0;         // the file of the newest frame
  std::deque<Line> due_ WIRCAM_GUARDED_BY(mutex_);            // for open files, by file
  std::deque<Waiting> waiting_ WIRCAM_GUARDED_BY(mutex_);     // for files still to open
  static constexpr size_t kMaxWaiting = 1024;                 // each (past it: the oldest go)
  static constexpr GstClockTime kLineDuration = GST_MSECOND;  // an event, not a caption to read
  static constexpr GstClockTime kGapAhead = GST_SECOND;       // a GAP event's reach past its frame
};

}  // namespace wircam::recorder
