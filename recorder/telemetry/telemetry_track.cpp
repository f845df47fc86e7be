#include "telemetry/telemetry_track.h"

#include <gst/app/gstappsrc.h>

namespace wircam::recorder {

void TelemetryTrack::write(const std::string& json, GstClockTime pts,
                           const std::function<bool(GstClockTime newest)>& tooLate) {
  if (!GST_CLOCK_TIME_IS_VALID(pts)) return;
  // The lock spans the push so that buffers enter the appsrc in time order.
  MutexLock lock(mutex_);
  if (tooLate && tooLate(last_)) return;
  GstBuffer* buffer =
      json.empty() ? gst_buffer_new() : gst_buffer_new_memdup(json.data(), json.size());
  last_ = std::max(last_, pts);
  GST_BUFFER_PTS(buffer) = last_;
  GST_BUFFER_DURATION(buffer) = GST_MSECOND;  // an event, not a caption to read
  gst_app_src_push_buffer(GST_APP_SRC(source_), buffer);
}

}  // namespace wircam::recorder
