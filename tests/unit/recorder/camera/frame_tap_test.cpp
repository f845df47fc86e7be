// A frame handed on by FrameTap carries its own time: the running time it
// was stamped with (wircsrc's kernel receive time), on the wall clock, as
// the recording keeps it; not the moment a listener got it.
#include "camera/frame_tap.h"

#include <gst/app/gstappsrc.h>
#include <gst/check/gsttestclock.h>
#include <gst/gst.h>
#include <gtest/gtest.h>

#include <atomic>

#include "wait_for.h"

namespace wircam::recorder {
namespace {

// appsrc ! SINK on a test clock: a frame stamped 300 ms of running time
// before the pipeline's now; the time the tap says, against the wall clock
// when it said it (not when the frame was pushed: on a busy machine the
// appsrc's thread takes it tens of ms later, and the pipeline's time,
// held still, does not move meanwhile).
int64_t lagOfTappedFrame(const char* sink, bool byPad) {
  std::string description = std::string("appsrc name=in is-live=true format=time ! ") + sink;
  GstElement* pipeline = gst_parse_launch(description.c_str(), nullptr);
  GstElement* in = gst_bin_get_by_name(GST_BIN(pipeline), "in");
  GstElement* out = gst_bin_get_by_name(GST_BIN(pipeline), "out");
  gst_app_src_set_caps(GST_APP_SRC(in), gst_caps_from_string("image/jpeg"));
  FrameTap tap;
  GstPad* pad = gst_element_get_static_pad(out, "sink");
  if (byPad)
    tap.attachPad(pad);
  else
    tap.attach(out);
  gst_object_unref(pad);
  std::atomic<int64_t> said = 0, saidAt = 0;
  tap.listen([&](GstSample* sample) {
    int64_t wallTime = tap.wallTimeNs(sample);
    saidAt = g_get_real_time() * 1000;
    said = wallTime;
  });
  // The pipeline's time moves only when the test moves it: 400 ms of it
  // run at once, and the frame was stamped at 100 ms.
  GstClock* clock = gst_test_clock_new_with_start_time(GST_SECOND);
  gst_pipeline_use_clock(GST_PIPELINE(pipeline), clock);
  gst_element_set_state(pipeline, GST_STATE_PLAYING);
  gst_element_get_state(pipeline, nullptr, nullptr, GST_CLOCK_TIME_NONE);
  gst_test_clock_advance_time(GST_TEST_CLOCK(clock), 400 * GST_MSECOND);
  GstBuffer* frame = gst_buffer_new_allocate(nullptr, 16, nullptr);
  GST_BUFFER_PTS(frame) = gst_element_get_current_running_time(pipeline) - 300 * GST_MSECOND;
  gst_app_src_push_buffer(GST_APP_SRC(in), frame);
  testing::waitFor([&] { return said != 0; });
  gst_element_set_state(pipeline, GST_STATE_NULL);
  tap.detach();
  gst_object_unref(in);
  gst_object_unref(out);
  gst_object_unref(pipeline);
  gst_object_unref(clock);
  return said == 0 ? INT64_MIN : saidAt - said;
}

TEST(FrameTap, AFramesTimeIsItsRunningTimeOnTheWallClockNotItsArrival) {
  gst_init(nullptr, nullptr);
  constexpr int64_t kMs = 1000000;
  // An appsink (the live JPEG branch), and a pad (the recording's H.264).
  int64_t appsink = lagOfTappedFrame("appsink name=out sync=false async=false", false);
  EXPECT_GT(appsink, 295 * kMs);
  EXPECT_LT(appsink, 400 * kMs);  // (stamped at its arrival, it would be 0)
  int64_t pad = lagOfTappedFrame("fakesink name=out sync=false async=false", true);
  EXPECT_GT(pad, 295 * kMs);
  EXPECT_LT(pad, 400 * kMs);
}

}  // namespace
}  // namespace wircam::recorder
