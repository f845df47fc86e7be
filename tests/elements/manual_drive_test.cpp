// wirccontrol's `drive` action against the simulated device: a command by
// hand leaves at once within the pulse limits, the follower keeps off it,
// and without a newer one the vehicle is at neutral after drive-timeout.
#include <gst/check/gstharness.h>
#include <gst/gst.h>
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <limits>
#include <string>

#include "wait_for.h"
#include "wirc/device.h"
#include "wirc_tag_meta.h"

namespace {

using namespace wircam;
using std::chrono::milliseconds;
using wircam::testing::waitFor;
using Clock = std::chrono::steady_clock;

constexpr size_t kSteering = 0, kThrottle = 1;  // channels 1 and 2

struct DrivenControl {
  std::unique_ptr<wirc::Device> device;
  GstHarness* harness = nullptr;
  GstElement* control = nullptr;
  GstBus* bus = gst_bus_new();

  explicit DrivenControl(const std::string& properties = "") {
    auto started = wirc::Device::start({.port = 0}, nullptr);
    EXPECT_TRUE(started.has_value()) << started.error();
    device = std::move(*started);
    auto description =
        "wirccontrol host=127.0.0.1 port=" + std::to_string(device->port()) + " " + properties;
    harness = gst_harness_new_parse(description.c_str());
    control = gst_harness_find_element(harness, "wirccontrol");
    gst_element_set_bus(harness->element, bus);
    gst_harness_set_src_caps_str(harness, "video/x-raw,format=GRAY8,width=352,height=288");
    gst_harness_play(harness);
    EXPECT_TRUE(waitFor([&] {
      gboolean has = FALSE;
      g_object_get(control, "has-control", &has, nullptr);
      return has == TRUE;
    }));
  }
  ~DrivenControl() {
    gst_object_unref(control);
    gst_harness_teardown(harness);
    gst_object_unref(bus);
  }
  bool drive(double steering, double throttle) {
    gboolean obeyed = FALSE;
    g_signal_emit_by_name(control, "drive", steering, throttle, &obeyed);
    return obeyed;
  }
  uint16_t pulse(size_t channel) const { return device->outputs().pulses[channel]; }
  // The `reason` of each wirc-drive message posted so far.
  std::vector<std::string> driveReasons() {
    std::vector<std::string> reasons;
    while (GstMessage* m = gst_bus_pop_filtered(bus, GST_MESSAGE_ELEMENT)) {
      const GstStructure* s = gst_message_get_structure(m);
      if (gst_structure_has_name(s, "wirc-drive"))
        reasons.emplace_back(gst_structure_get_string(s, "reason"));
      gst_message_unref(m);
    }
    return reasons;
  }
};

// A buffer with one tag far to the right: the follower would steer right.
GstBuffer* bufferWithATagOnTheRight() {
  GstBuffer* buffer = gst_buffer_new_allocate(nullptr, 16, nullptr);
  WircTagMeta* meta = gst_buffer_add_wirc_tag_meta(buffer, 352, 288);
  WircTag tag{};
  double corners[8] = {300, 124, 340, 124, 340, 164, 300, 164};
  std::copy(corners, corners + 8, tag.corners);
  tag.cx = 320;
  tag.cy = 144;
  g_array_append_val(meta->tags, tag);
  return buffer;
}

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
  auto reasons = c.driveReasons();
  EXPECT_EQ(reasons, (std::vector<std::string>{"command", "command"}));
}

TEST(ManualDrive, WithoutANewerCommandTheVehicleIsAtNeutralAfterTheDriveTimeout) {
  DrivenControl c("drive-timeout=300");
  auto sent = Clock::now();
  c.drive(-1.0, 0.5);
  ASSERT_TRUE(waitFor([&] { return c.pulse(kSteering) == 1000; }));
  // Held while the timeout runs...
  std::this_thread::sleep_for(milliseconds(150));
  EXPECT_EQ(c.pulse(kSteering), 1000);
  // ...and neutral once it has passed, with no frame coming at all.
  ASSERT_TRUE(waitFor([&] { return c.pulse(kSteering) == 1500 && c.pulse(kThrottle) == 1500; }));
  EXPECT_GE(Clock::now() - sent, milliseconds(300));
  std::vector<std::string> seen;
  EXPECT_TRUE(waitFor([&] {
    for (auto& r : c.driveReasons()) seen.push_back(r);
    return !seen.empty() && seen.back() == "dead-man";
  }));
}

TEST(ManualDrive, CommandsKeepItGoingAndNotANumberMeansNeutral) {
  DrivenControl c("drive-timeout=200");
  // A command every 100 ms for 600 ms, three times the timeout. Between a
  // command's arrival (50 ms on) and the earliest the dead-man may act
  // (150 ms, a margin under 200) the car must be driving. Timed from the
  // last command sent, so a stall of this thread cannot fail the test.
  auto until = Clock::now() + milliseconds(600);
  auto lastCommand = Clock::now();
  c.drive(0, 1.0);
  bool everNeutral = false;
  while (Clock::now() < until) {
    std::this_thread::sleep_for(milliseconds(10));
    auto since = Clock::now() - lastCommand;
    if (since > milliseconds(50) && since < milliseconds(150) && c.pulse(kThrottle) == 1500)
      everNeutral = true;
    if (since >= milliseconds(100)) {
      lastCommand = Clock::now();
      c.drive(0, 1.0);
    }
  }
  EXPECT_FALSE(everNeutral);
  c.drive(std::numeric_limits<double>::quiet_NaN(), 1.0);
  EXPECT_TRUE(waitFor([&] { return c.pulse(kThrottle) == 1500; }));
  auto reasons = c.driveReasons();
  ASSERT_FALSE(reasons.empty());
  EXPECT_EQ(reasons.back(), "not a number: neutral");
}

TEST(ManualDrive, BeforeTheElementStartsNothingIsDriven) {
  GstElement* control = gst_element_factory_make("wirccontrol", nullptr);
  gboolean obeyed = TRUE;
  g_signal_emit_by_name(control, "drive", 0.0, 1.0, &obeyed);
  EXPECT_FALSE(obeyed);
  gst_object_unref(control);
}

}  // namespace
