// When, by the wall clock, a pipeline running time was: what file names and
// the "utc" of telemetry say.
#pragma once

#include <gst/gst.h>

#include <cstdint>

namespace wircam::recorder {

// Unix milliseconds of `runningTime` on `element`'s pipeline clock: now,
// less how long ago that running time was. Now, if either is unknown.
inline int64_t unixMsOf(GstElement* element, GstClockTime runningTime) {
  int64_t now = g_get_real_time() / 1000;
  GstClockTime running = gst_element_get_current_running_time(element);
  if (!GST_CLOCK_TIME_IS_VALID(running) || !GST_CLOCK_TIME_IS_VALID(runningTime)) return now;
  return now - GST_CLOCK_DIFF(runningTime, running) / static_cast<int64_t>(GST_MSECOND);
}

}  // namespace wircam::recorder
