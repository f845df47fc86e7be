// wirccontrol in a GstHarness (whose clock is a test clock) steering the
// simulated device over loopback: for the tests of its timing.
#pragma once

#include <gst/check/gstharness.h>
#include <gst/gst.h>
#include <gtest/gtest.h>

#include <memory>
#include <string>
#include <vector>

#include "devices/wirc/device.h"
#include "wait_for.h"
#include "wirc_tag_meta.h"

namespace wircam::testing {

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
    EXPECT_TRUE(wircam::testing::waitFor([&] {
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
inline GstBuffer* bufferWithATagOnTheRight() {
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

}  // namespace wircam::testing
