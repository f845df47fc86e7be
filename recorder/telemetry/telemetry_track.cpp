#include "telemetry/telemetry_track.h"

#include <gst/app/gstappsrc.h>

#include <utility>

namespace wircam::recorder {

bool TelemetryTrack::write(const std::string& json, GstClockTime pts, GstClockTime fileStart) {
  if (!source_ || !GST_CLOCK_TIME_IS_VALID(pts)) return false;
  // The lock spans the push so that buffers enter the appsrc in time order.
  MutexLock lock(mutex_);
  if (openFile_ == 0 || fileStart > openStart_) {
    if (waiting_.size() == kMaxWaiting) waiting_.pop_front();
    waiting_.push_back({json, pts, fileStart});
    return true;
  }
  if (fileStart == openStart_) {
    pushLine(json, pts, openFile_);
    return true;
  }
  // The file before, as long as the newest has not begun: after its first
  // buffer, the text track has moved on.
  if (fileStart != previousStart_ || sentFile_ == openFile_) return false;
  pushLine(json, pts, openFile_ - 1);
  return true;
}

uint64_t TelemetryTrack::fileOpened(GstClockTime start) {
  MutexLock lock(mutex_);
  ++openFile_;
  previousStart_ = std::exchange(openStart_, start);
  while (!waiting_.empty() && waiting_.front().fileStart <= start) {
    if (waiting_.front().fileStart == start)
      pushLine(waiting_.front().json, waiting_.front().pts, openFile_);
    waiting_.pop_front();
  }
  return openFile_;
}

void TelemetryTrack::heartbeat(GstClockTime frameTime) {
  if (!source_) return;
  MutexLock lock(mutex_);
  if (openFile_ == 0) return;
  if (!gapsAhead_) return pushGap(frameTime + 1, kLineDuration, openFile_);
  if (sentFile_ == openFile_ && frameTime + kGapLead / 2 < promised_) return;
  pushGap(frameTime + 1, kGapLead, openFile_);
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
  if (source_) gst_app_src_end_of_stream(GST_APP_SRC(source_));
}

bool TelemetryTrack::allSent() const {
  return !source_ || gst_app_src_get_current_level_buffers(GST_APP_SRC(source_)) == 0;
}

void TelemetryTrack::pushLine(const std::string& json, GstClockTime pts, uint64_t file) {
  moveTo(file);
  last_ = std::max(last_, pts);
  send(gst_buffer_new_memdup(json.data(), json.size()), last_, kLineDuration, file);
  if (gapsAhead_ && promised_ > last_ + kLineDuration)
    pushGap(last_ + kLineDuration, promised_ - last_ - kLineDuration, file);
}

void TelemetryTrack::pushGap(GstClockTime from, GstClockTime duration, uint64_t file) {
  moveTo(file);
  // An empty sample, for mp4mux: the lines after it must not go before it.
  if (!gapsAhead_) last_ = std::max(last_, from);
  promised_ = std::max(promised_, from + duration);
  GstBuffer* gap = gst_buffer_new();
  GST_BUFFER_FLAG_SET(gap, GST_BUFFER_FLAG_GAP);
  send(gap, from, duration, file);
}

void TelemetryTrack::moveTo(uint64_t file) {
  if (file == sentFile_) return;
  sentFile_ = file;
  last_ = 0;
  promised_ = 0;
}

void TelemetryTrack::send(GstBuffer* buffer, GstClockTime pts, GstClockTime duration,
                          uint64_t file) {
  GST_BUFFER_PTS(buffer) = pts;
  GST_BUFFER_DURATION(buffer) = duration;
  GST_BUFFER_OFFSET(buffer) = file;
  gst_app_src_push_buffer(GST_APP_SRC(source_), buffer);
}

}  // namespace wircam::recorder
