#include "telemetry/telemetry_track.h"

#include <algorithm>
#include <utility>

namespace wircam::recorder {

bool TelemetryTrack::write(const std::string& json, GstClockTime pts, GstClockTime fileStart) {
  if (!outlet_ || !GST_CLOCK_TIME_IS_VALID(pts)) return false;
  MutexLock lock(mutex_);
  if (ended_) return false;
  if (openFile_ == 0 || fileStart > openStart_) {
    if (waiting_.size() == kMaxWaiting) waiting_.pop_front();
    waiting_.push_back({json, pts, fileStart});
    return true;
  }
  uint64_t file = openFile_;
  // The file before, as long as nothing of the newest has gone out: after
  // its first buffer, the text track has moved on.
  if (fileStart != openStart_) {
    if (fileStart != previousStart_ || sentFile_ == openFile_) return false;
    file = openFile_ - 1;
  }
  if (due_.size() == kMaxWaiting) due_.pop_front();
  // By file: a line of the file before goes ahead of the newest's.
  auto later =
      std::find_if(due_.begin(), due_.end(), [&](const Line& due) { return due.file > file; });
  due_.insert(later, {json, pts, file});
  return true;
}

uint64_t TelemetryTrack::fileOpened(GstClockTime start) {
  MutexLock lock(mutex_);
  ++openFile_;
  previousStart_ = std::exchange(openStart_, start);
  while (!waiting_.empty() && waiting_.front().fileStart <= start) {
    if (waiting_.front().fileStart == start)
      due_.push_back({std::move(waiting_.front().json), waiting_.front().pts, openFile_});
    waiting_.pop_front();
  }
  return openFile_;
}

void TelemetryTrack::beforeFrame(GstClockTime frameTime, uint64_t file) {
  if (!outlet_) return;
  MutexLock lock(mutex_);
  // A file's lines wait for its second frame: until its first has gone in,
  // its muxer cannot give them a turn (its frames' input has no segment).
  bool started = std::exchange(framesFile_, file) == file;
  std::vector<GstBuffer*> lines;
  for (auto line = due_.begin(); line != due_.end();) {
    if (line->file < file || (started && line->file == file && line->pts <= frameTime)) {
      lines.push_back(stamp(*line));
      line = due_.erase(line);
    } else {
      ++line;
    }
  }
  moveTo(file);
  GstClockTime from = frameTime + 1;
  GstClockTime reach = kLineDuration;
  if (gapsAreSamples_) {
    from = startAfterTheLast(from);
  } else {
    if (lines.empty() && !ended_ && file == gapFile_ && frameTime < gapEnd_) return;
    reach = kGapAhead;
    gapFile_ = file;
    gapEnd_ = from + reach;
  }
  GstBuffer* gap = gst_buffer_new();
  GST_BUFFER_FLAG_SET(gap, GST_BUFFER_FLAG_GAP);
  outlet_->beforeFrame(std::move(lines), bufferOf(gap, from, reach, file));
}

GstPadProbeReturn TelemetryTrack::passGap(GstPad* pad, GstPadProbeInfo* info, bool asEvent) {
  GstBuffer* buffer = GST_PAD_PROBE_INFO_BUFFER(info);
  if (!asEvent) {
    buffer = gst_buffer_make_writable(buffer);
    GST_BUFFER_FLAG_UNSET(buffer, GST_BUFFER_FLAG_GAP);
    GST_PAD_PROBE_INFO_DATA(info) = buffer;
    return GST_PAD_PROBE_PASS;
  }
  gst_pad_push_event(pad, gst_event_new_gap(GST_BUFFER_PTS(buffer), GST_BUFFER_DURATION(buffer)));
  return GST_PAD_PROBE_DROP;
}

void TelemetryTrack::end() {
  if (!outlet_) return;
  MutexLock lock(mutex_);
  if (std::exchange(ended_, true)) return;
  std::vector<GstBuffer*> lines;
  for (const Line& line : due_) lines.push_back(stamp(line));
  due_.clear();
  waiting_.clear();  // for files that will not open
  outlet_->end(std::move(lines));
}

void TelemetryTrack::framesEnd() {
  if (!outlet_) return;
  MutexLock lock(mutex_);
  outlet_->framesEnd();
}

bool TelemetryTrack::allSent() const { return !outlet_ || outlet_->allSent(); }

GstBuffer* TelemetryTrack::stamp(const Line& line) {
  moveTo(line.file);
  GstClockTime at =
      gapsAreSamples_ ? startAfterTheLast(line.pts) : (last_ = std::max(last_, line.pts));
  return bufferOf(gst_buffer_new_memdup(line.json.data(), line.json.size()), at, kLineDuration,
                  line.file);
}

GstClockTime TelemetryTrack::startAfterTheLast(GstClockTime pts) {
  GstClockTime at = std::max(last_, pts);
  last_ = at + kLineDuration;
  return at;
}

void TelemetryTrack::moveTo(uint64_t file) {
  if (file == sentFile_) return;
  sentFile_ = file;
  last_ = 0;
}

GstBuffer* TelemetryTrack::bufferOf(GstBuffer* buffer, GstClockTime pts, GstClockTime duration,
                                    uint64_t file) {
  GST_BUFFER_PTS(buffer) = pts;
  GST_BUFFER_DURATION(buffer) = duration;
  GST_BUFFER_OFFSET(buffer) = file;
  return buffer;
}

}  // namespace wircam::recorder
