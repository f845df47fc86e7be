// wirccontrol's lost-timeout counts the buffers' running time: the target
// is held through a short gap and given up once lost-timeout of stream time
// has passed without it, however fast the buffers come.
#include <gst/check/gstharness.h>
#include <gst/gst.h>
#include <gtest/gtest.h>

#include <optional>

#include "driven_control.h"

namespace {

using wircam::testing::bufferWithATagOnTheRight;
using wircam::testing::DrivenControl;

struct ControlStep {
  bool targetVisible = false;
  guint steeringPulse = 0;
};

// Pushes `buffer` at `pts` and reads the wirc-control message it caused.
std::optional<ControlStep> stepAt(DrivenControl& c, GstBuffer* buffer, GstClockTime pts) {
  GST_BUFFER_PTS(buffer) = pts;
  gst_buffer_unref(gst_harness_push_and_pull(c.harness, buffer));
  std::optional<ControlStep> step;
  while (GstMessage* m = gst_bus_pop_filtered(c.bus, GST_MESSAGE_ELEMENT)) {
    const GstStructure* s = gst_message_get_structure(m);
    if (gst_structure_has_name(s, "wirc-control")) {
      step.emplace();
      gboolean visible = FALSE;
      gst_structure_get_boolean(s, "target-visible", &visible);
      step->targetVisible = visible;
      gst_structure_get_uint(s, "steering-pulse", &step->steeringPulse);
    }
    gst_message_unref(m);
  }
  return step;
}

GstBuffer* bufferWithoutTags() { return gst_buffer_new_allocate(nullptr, 16, nullptr); }

TEST(WircControlLostTimeout, CountsTheBuffersRunningTime) {
  DrivenControl c("lost-timeout=500");
  // Two frames with the tag: the slew-rate limit lets the steering move
  // only once time has passed between them.
  ASSERT_TRUE(stepAt(c, bufferWithATagOnTheRight(), 0));
  auto seen = stepAt(c, bufferWithATagOnTheRight(), 100 * GST_MSECOND);
  ASSERT_TRUE(seen && seen->targetVisible);
  ASSERT_NE(seen->steeringPulse, 1500u);  // steering towards it

  // Out of view for 400 ms of stream time: the last command holds.
  auto gap = stepAt(c, bufferWithoutTags(), 500 * GST_MSECOND);
  ASSERT_TRUE(gap);
  EXPECT_FALSE(gap->targetVisible);
  EXPECT_EQ(gap->steeringPulse, seen->steeringPulse);

  // 501 ms after it was last seen: lost, both channels to neutral.
  auto lost = stepAt(c, bufferWithoutTags(), 601 * GST_MSECOND);
  ASSERT_TRUE(lost);
  EXPECT_EQ(lost->steeringPulse, 1500u);
}

TEST(WircControlLostTimeout, TimeThatStepsBackStartsAfresh) {
  DrivenControl c("lost-timeout=500");
  ASSERT_TRUE(stepAt(c, bufferWithATagOnTheRight(), 10 * GST_SECOND));
  auto steering = stepAt(c, bufferWithATagOnTheRight(), 10 * GST_SECOND + 100 * GST_MSECOND);
  ASSERT_TRUE(steering);
  ASSERT_NE(steering->steeringPulse, 1500u);
  // A new stream whose time starts again: nothing seen before it counts,
  // so no stale command is held for the ten seconds that "went back".
  auto after = stepAt(c, bufferWithoutTags(), 0);
  ASSERT_TRUE(after);
  EXPECT_EQ(after->steeringPulse, 1500u);
}

}  // namespace
