// wirccontrol's `drive` action against the simulated device: a command by
// hand leaves at once within the pulse limits, the follower keeps off it,
// and without a newer one the vehicle is at neutral after drive-timeout of
// the pipeline clock's time.
#include <gst/check/gstharness.h>
#include <gst/check/gsttestclock.h>
#include <gst/gst.h>
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <limits>
#include <string>

#include "driven_control.h"

namespace {

using namespace wircam;
using std::chrono::milliseconds;
using wircam::testing::bufferWithATagOnTheRight;
using wircam::testing::DrivenControl;
using wircam::testing::kSteering;
using wircam::testing::kThrottle;
using wircam::testing::waitFor;

TEST(ManualDrive, ACommandLeavesAtOnceWithinTheLimitsAndHoldsOffTheFollower) {
  // The dead-man is another test's: here it must not act while a stalled
  // test thread (a sanitizer's, a loaded machine's) waits.
  DrivenControl c("drive-timeout=5000");
  // Half left, full ahead: throttle is scaled by max-throttle (0.8) and
  // starts past the deadband (50 µs): 1500 + 50 + 0.8 × 450 = 1910.
  EXPECT_TRUE(c.drive(0.5, 1.0));
  EXPECT_TRUE(waitFor([&] { return c.pulse(kThrottle) == 1910; }));
  EXPECT_EQ(c.pulse(kSteering), 1750);
  // Beyond ±1 is clamped: never past max (2000).
  c.drive(7.0, -3.0);
  EXPECT_TRUE(waitFor([&] { return c.pulse(kSteering) == 2000; }));
  EXPECT_EQ(c.pulse(kThrottle), 1500 - 50 - 360);
  // A frame with a tag to follow does not take the vehicle from the driver.
  gst_buffer_unref(gst_harness_push_and_pull(c.harness, bufferWithATagOnTheRight()));
  std::this_thread::sleep_for(milliseconds(50));
  EXPECT_EQ(c.pulse(kSteering), 2000);
  // The frame's wirc-control message says what the vehicle is sent: the
  // command by hand, not the follower's (a recording's telemetry showed
  // neutral while the car drove).
  std::vector<std::string> reasons;
  int controls = 0;
  while (GstMessage* m = gst_bus_pop_filtered(c.bus, GST_MESSAGE_ELEMENT)) {
    const GstStructure* s = gst_message_get_structure(m);
    if (gst_structure_has_name(s, "wirc-drive"))
      reasons.emplace_back(gst_structure_get_string(s, "reason"));
    if (gst_structure_has_name(s, "wirc-control")) {
      ++controls;
      gboolean manual = FALSE;
      guint steering = 0;
      gst_structure_get_boolean(s, "manual", &manual);
      gst_structure_get_uint(s, "steering-pulse", &steering);
      EXPECT_TRUE(manual);
      EXPECT_EQ(steering, 2000u);
    }
    gst_message_unref(m);
  }
  EXPECT_EQ(controls, 1);
  EXPECT_EQ(reasons, (std::vector<std::string>{"command", "command"}));
}

// The dead-man runs on the pipeline clock: the harness's test clock shows
// its deadline and fires it, with no waiting.
TEST(ManualDrive, WithoutANewerCommandTheVehicleIsAtNeutralAfterTheDriveTimeout) {
  DrivenControl c("drive-timeout=300");
  GstTestClock* clock = gst_harness_get_testclock(c.harness);
  GstClockTime sent = gst_clock_get_time(GST_CLOCK(clock));
  c.drive(-1.0, 0.5);
  ASSERT_TRUE(waitFor([&] { return c.pulse(kSteering) == 1000; }));
  // Held until the clock reaches the command's time plus drive-timeout...
  ASSERT_TRUE(gst_test_clock_timed_wait_for_multiple_pending_ids(clock, 1, 5000, nullptr));
  EXPECT_EQ(gst_test_clock_get_next_entry_time(clock), sent + 300 * GST_MSECOND);
  EXPECT_EQ(c.pulse(kSteering), 1000);
  // ...and neutral once it has, with no frame coming at all.
  ASSERT_TRUE(gst_harness_crank_single_clock_wait(c.harness));
  EXPECT_TRUE(waitFor([&] { return c.pulse(kSteering) == 1500 && c.pulse(kThrottle) == 1500; }));
  std::vector<std::string> seen;
  EXPECT_TRUE(waitFor([&] {
    for (auto& r : c.driveReasons()) seen.push_back(r);
    return !seen.empty() && seen.back() == "dead-man";
  }));
  gst_object_unref(clock);
}

TEST(ManualDrive, EachCommandMovesTheDeadlineAndNotANumberMeansNeutral) {
  DrivenControl c("drive-timeout=200");
  GstTestClock* clock = gst_harness_get_testclock(c.harness);
  // A command every 100 ms of pipeline time for 600 ms, three times the
  // timeout: each earlier deadline has passed, yet none acts.
  c.drive(0, 1.0);
  for (int i = 0; i < 6; ++i) {
    gst_test_clock_advance_time(clock, 100 * GST_MSECOND);
    GstClockID due = gst_test_clock_process_next_clock_id(clock);
    EXPECT_EQ(due, nullptr) << "a replaced deadline acted after " << (i + 1) * 100 << " ms";
    if (due) gst_clock_id_unref(due);
    c.drive(0, 1.0);
  }
  EXPECT_TRUE(waitFor([&] { return c.pulse(kThrottle) == 1910; }));
  c.drive(std::numeric_limits<double>::quiet_NaN(), 1.0);
  EXPECT_TRUE(waitFor([&] { return c.pulse(kThrottle) == 1500; }));
  auto reasons = c.driveReasons();
  ASSERT_FALSE(reasons.empty());
  EXPECT_EQ(reasons.back(), "not a number: neutral");
  gst_object_unref(clock);
}

TEST(ManualDrive, BeforeTheElementStartsNothingIsDriven) {
  GstElement* control = gst_element_factory_make("wirccontrol", nullptr);
  gboolean obeyed = TRUE;
  g_signal_emit_by_name(control, "drive", 0.0, 1.0, &obeyed);
  EXPECT_FALSE(obeyed);
  gst_object_unref(control);
}

}  // namespace
