// When, by the wall clock, a pipeline running time was: what file names and
// the "utc" of telemetry say.
#pragma once

#include <gst/gst.h>

#include <cstdint>

namespace wircam::recorder {

// Unix nanoseconds of `runningTime` on `element`'s pipeline clock: now,
// less how long ago that running time was. Now, if either is unknown.
// The two clocks are read as a pair within a millisecond of each other: a
// thread preempted between the two reads (a loaded machine) would put a
// segment's start tens of milliseconds off its frames, and consecutive
// segments would overlap in time; such a read is made again.
inline int64_t unixNsOf(GstElement* element, GstClockTime runningTime) {
  constexpr int kAttempts = 5;
  for (int attempt = 1;; ++attempt) {
    GstClockTime before = gst_element_get_current_running_time(element);
    int64_t now = g_get_real_time() * 1000;
    GstClockTime after = gst_element_get_current_running_time(element);
    if (!GST_CLOCK_TIME_IS_VALID(before) || !GST_CLOCK_TIME_IS_VALID(after) ||
        !GST_CLOCK_TIME_IS_VALID(runningTime))
      return now;
    if (after - before <= GST_MSECOND || attempt == kAttempts)
      return now - GST_CLOCK_DIFF(runningTime, before + (after - before) / 2);
  }
}

// The same in Unix milliseconds (file names, telemetry's "utc").
inline int64_t unixMsOf(GstElement* element, GstClockTime runningTime) {
  int64_t ns = unixNsOf(element, runningTime);
  return ns / 1000000 - (ns % 1000000 < 0 ? 1 : 0);
}

}  // namespace wircam::recorder
