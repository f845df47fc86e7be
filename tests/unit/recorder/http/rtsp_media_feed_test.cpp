// A media's source takes the camera's frames only while it is PLAYING: a
// frame pushed while its pipeline goes to PLAYING was stamped with the
// clock's whole time (the source has the clock before its base time), and
// the client, behind a sink that waits for that time, got nothing.
#include "http/rtsp_media_feed.h"

#include <gst/app/gstappsink.h>
#include <gst/check/gsttestclock.h>
#include <gtest/gtest.h>

#include <string>

namespace wircam::recorder {
namespace {

GstSample* jpegSample() {
  GstBuffer* buffer = gst_buffer_new_allocate(nullptr, 64, nullptr);
  GstCaps* caps = gst_caps_from_string("image/jpeg, width=(int)352, height=(int)288");
  GstSample* sample = gst_sample_new(buffer, caps, nullptr, nullptr);
  gst_buffer_unref(buffer);
  gst_caps_unref(caps);
  return sample;
}

guint queuedIn(GstElement* source) {
  guint64 buffers = 0;
  g_object_get(source, "current-level-buffers", &buffers, nullptr);
  return static_cast<guint>(buffers);
}

TEST(RtspMediaFeed, AFrameWaitsForNoMediaThatIsNotPlayingYet) {
  gst_init(nullptr, nullptr);
  std::string description =
      std::string(kRtspFrameSource) + " ! appsink name=out sync=false async=false";
  GstElement* pipeline = gst_parse_launch(description.c_str(), nullptr);
  GstElement* source = gst_bin_get_by_name(GST_BIN(pipeline), "frames");
  GstElement* out = gst_bin_get_by_name(GST_BIN(pipeline), "out");
  GstClock* clock = gst_test_clock_new_with_start_time(1000 * GST_SECOND);
  gst_pipeline_use_clock(GST_PIPELINE(pipeline), clock);
  RtspMediaFeed feed;
  feed.add(source);
  GstSample* frame = jpegSample();

  // What the pipeline does on its way to PLAYING: the source has the clock
  // and its base time is still 0.
  gst_element_set_state(pipeline, GST_STATE_PAUSED);
  gst_element_set_clock(source, clock);
  feed.push(frame);
  EXPECT_EQ(queuedIn(source), 0u);

  gst_element_set_state(pipeline, GST_STATE_PLAYING);
  gst_element_get_state(pipeline, nullptr, nullptr, GST_CLOCK_TIME_NONE);
  gst_test_clock_advance_time(GST_TEST_CLOCK(clock), 40 * GST_MSECOND);
  feed.push(frame);
  GstSample* sent = gst_app_sink_try_pull_sample(GST_APP_SINK(out), 5 * GST_SECOND);
  ASSERT_NE(sent, nullptr);
  // Stamped with its running time, as a sink that syncs expects.
  EXPECT_EQ(GST_BUFFER_PTS(gst_sample_get_buffer(sent)), 40 * GST_MSECOND);
  gst_sample_unref(sent);

  // A media that went takes nothing more, PLAYING or not.
  feed.removeWithin(pipeline);
  feed.push(frame);
  EXPECT_EQ(gst_app_sink_try_pull_sample(GST_APP_SINK(out), 200 * GST_MSECOND), nullptr);
  gst_sample_unref(frame);
  gst_element_set_state(pipeline, GST_STATE_NULL);
  gst_object_unref(out);
  gst_object_unref(source);
  gst_object_unref(pipeline);
  gst_object_unref(clock);
}

}  // namespace
}  // namespace wircam::recorder
