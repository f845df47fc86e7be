#include "telemetry_track.h"

#include <gst/app/gstappsrc.h>

namespace wircam::recorder {

void TelemetryTrack::write(const std::string& json, GstClockTime pts) {
  if (!GST_CLOCK_TIME_IS_VALID(pts)) return;
  last_ = std::max(last_, pts);
  GstBuffer* buffer = gst_buffer_new_memdup(json.data(), json.size());
  GST_BUFFER_PTS(buffer) = last_;
  GST_BUFFER_DURATION(buffer) = GST_MSECOND;  // an event, not a caption to read
  gst_app_src_push_buffer(GST_APP_SRC(source_), buffer);
}

}  // namespace wircam::recorder
