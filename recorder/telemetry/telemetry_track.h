// The telemetry as a timed text track inside the recording: each JSON line
// becomes one UTF-8 text buffer at the running time it belongs to, tagged
// with the file it is for.
//
// Files are numbered as they open (1, 2, ...); a buffer's offset
// (GST_BUFFER_OFFSET) is its file's number, which is how the SegmentWriter,
// on the appsrc's thread, knows when the text moves on to the next file.
#pragma once

#include <gst/gst.h>

#include <cstdint>
#include <deque>
#include <string>

#include "common/mutex.h"

namespace wircam::recorder {

class TelemetryTrack {
 public:
  // `source` is the stream's appsrc (text/x-raw, format=utf8); borrowed.
  // Null: the files have no text track, and every line is refused.
  // `gapsAhead`: the muxer takes gaps as GAP events (matroskamux), so the
  // heartbeat may promise a stretch ahead of the frames (heartbeat()).
  TelemetryTrack(GstElement* source, bool gapsAhead) : source_(source), gapsAhead_(gapsAhead) {}

  // A line for the file that starts at running time `fileStart`. A muxer
  // wants the timestamps of a track to rise, but events arrive a little out
  // of order (a detection is stamped with its frame's time, a little after
  // later statistics): such a line is placed at the latest time already
  // written; its own "pts" field keeps the exact time.
  // A line for a file not open yet waits for it; one for a file the track
  // has moved past is refused (false): it stays in the sidecar only.
  bool write(const std::string& json, GstClockTime pts, GstClockTime fileStart);

  // A file starting at `start` opened: the lines that waited for it go
  // out. Returns its number.
  uint64_t fileOpened(GstClockTime start);

  // A muxer hands on a frame only once every track has passed its time,
  // so a sparse text track would hold the video back: the text says it has
  // nothing until past the frame (a gap: an empty buffer flagged GAP, which
  // the SegmentWriter passes on as the muxer wants it). Called before each
  // frame reaches the muxer, on the frame's thread.
  // - With gapsAhead, one gap promises kGapLead, renewed once a frame comes
  //   within half of it: the text's thread wakes for gaps twice a second,
  //   not at every frame. A line is still written at its own time, behind the
  //   promise; as a line takes the muxer's idea of the track's position
  //   back to its time, the promise is restated after it, or the frames
  //   past the line would wait for a gap that no frame asks for.
  // - Otherwise (mp4mux: its gaps are empty samples, whose times must
  //   rise, and lines after them), a gap just after each frame.
  void heartbeat(GstClockTime frameTime);
  static constexpr GstClockTime kGapLead = GST_SECOND;
  static bool isGap(GstBuffer* buffer) {
    return GST_BUFFER_FLAG_IS_SET(buffer, GST_BUFFER_FLAG_GAP) && gst_buffer_get_size(buffer) == 0;
  }
  // A probe's answer to a gap (isGap) on its way out of `pad` to a muxer:
  // as a GAP event, for which matroskamux writes nothing, not even to the
  // file's duration (`asEvent`); or as a plain empty buffer, for mp4mux
  // (an aggregator, GStreamer 1.22), which stalls on GAP events.
  static GstPadProbeReturn passGap(GstPad* pad, GstPadProbeInfo* info, bool asEvent);

  // No more lines: the text track ends after the ones sent.
  void end();
  // Every line sent has left the track's queue for the muxer (where the
  // last may still wait for a frame).
  bool allSent() const;

  static uint64_t fileOf(GstBuffer* buffer) { return GST_BUFFER_OFFSET(buffer); }

 private:
  void pushLine(const std::string& json, GstClockTime pts, uint64_t file) WIRCAM_REQUIRES(mutex_);
  void pushGap(GstClockTime from, GstClockTime duration, uint64_t file) WIRCAM_REQUIRES(mutex_);
  // Buffers for `file` from now on: its times rise on their own.
  void moveTo(uint64_t file) WIRCAM_REQUIRES(mutex_);
  void send(GstBuffer* buffer, GstClockTime pts, GstClockTime duration, uint64_t file);

  struct Waiting {
    std::string json;
    GstClockTime pts, fileStart;
  };

  GstElement* source_;
  const bool gapsAhead_;
  Mutex mutex_;  // lines come from the main loop, heartbeats and openings from streaming
  uint64_t openFile_ WIRCAM_GUARDED_BY(mutex_) = 0;       // the newest file's number (0: none)
  GstClockTime openStart_ WIRCAM_GUARDED_BY(mutex_) = 0;  // and its start
  GstClockTime previousStart_ WIRCAM_GUARDED_BY(mutex_) = GST_CLOCK_TIME_NONE;  // the one before's
  uint64_t sentFile_ WIRCAM_GUARDED_BY(mutex_) = 0;        // the file of the newest buffer sent
  GstClockTime last_ WIRCAM_GUARDED_BY(mutex_) = 0;        // the newest line's time
  GstClockTime promised_ WIRCAM_GUARDED_BY(mutex_) = 0;    // where the newest gap ends
  std::deque<Waiting> waiting_ WIRCAM_GUARDED_BY(mutex_);  // for files still to open
  static constexpr size_t kMaxWaiting = 1024;
  static constexpr GstClockTime kLineDuration = GST_MSECOND;  // an event, not a caption to read
};

}  // namespace wircam::recorder
