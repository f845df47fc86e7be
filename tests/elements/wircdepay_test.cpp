// wircdepay in a GstHarness: datagrams in, whole JPEG frames out.
#include <gst/check/gstharness.h>
#include <gtest/gtest.h>

#include <algorithm>

#include "buffer_bytes.h"
#include "scene_frames.h"
#include "wirc/mjpeg_packet.h"
#include "wirc_bus_messages.h"

namespace {

using wircam::testing::sceneFrames;

class WircDepayTest : public ::testing::Test {
 protected:
  void SetUp() override {
    harness_ = gst_harness_new("wircdepay");
    ASSERT_NE(harness_, nullptr) << "wircdepay not found: is GST_PLUGIN_PATH set?";
    gst_harness_set_src_caps_str(harness_, "application/x-wirc-mjpeg");
  }
  void TearDown() override { gst_harness_teardown(harness_); }

  void push(const std::vector<uint8_t>& datagram) {
    GstBuffer* buffer = gst_buffer_new_memdup(datagram.data(), datagram.size());
    GST_BUFFER_PTS(buffer) = pts_;
    pts_ += GST_MSECOND;
    ASSERT_EQ(gst_harness_push(harness_, buffer), GST_FLOW_OK);
  }
  // The stream's time moves on by `gap` before the next datagram.
  void wait(GstClockTime gap) { pts_ += gap; }

  std::vector<uint8_t> pullBytes(GstBuffer** keep = nullptr) {
    GstBuffer* buffer = gst_harness_try_pull(harness_);
    if (!buffer) return {};
    auto bytes = bufferBytes(buffer);
    if (keep)
      *keep = buffer;
    else
      gst_buffer_unref(buffer);
    return bytes;
  }

  guint64 stat(const char* name) {
    GstStructure* stats = nullptr;
    g_object_get(harness_->element, "stats", &stats, nullptr);
    guint64 value = 0;
    gst_structure_get_uint64(stats, name, &value);
    gst_structure_free(stats);
    return value;
  }

  GstHarness* harness_ = nullptr;
  GstClockTime pts_ = GST_SECOND;
};

TEST_F(WircDepayTest, ReassemblesReorderedDuplicatedPacketsIntoTheSentFrame) {
  const auto& jpeg = sceneFrames()[0];
  auto packets = wircam::wirc::packetizeFrame(jpeg, 1, 1000);
  std::reverse(packets.begin(), packets.end());
  packets.insert(packets.begin() + 2, packets[1]);  // a duplicate while the frame is open
  for (const auto& p : packets) push(p);
  GstBuffer* buffer = nullptr;
  EXPECT_EQ(pullBytes(&buffer), jpeg);
  ASSERT_NE(buffer, nullptr);
  EXPECT_TRUE(GST_BUFFER_FLAG_IS_SET(buffer, GST_BUFFER_FLAG_DISCONT));
  EXPECT_TRUE(GST_BUFFER_PTS_IS_VALID(buffer));
  gst_buffer_unref(buffer);
  EXPECT_EQ(stat("packets-duplicate"), 1u);

  GstCaps* caps = gst_pad_get_current_caps(harness_->sinkpad);
  GstStructure* s = gst_caps_get_structure(caps, 0);
  int width = 0, height = 0;
  gst_structure_get_int(s, "width", &width);
  gst_structure_get_int(s, "height", &height);
  EXPECT_STREQ(gst_structure_get_name(s), "image/jpeg");
  EXPECT_EQ(width, 352);
  EXPECT_EQ(height, 288);
  gst_caps_unref(caps);
}

TEST_F(WircDepayTest, NeverPushesAFrameWithAMissingPacketAndMarksTheGap) {
  auto first = wircam::wirc::packetizeFrame(sceneFrames()[0], 1, 1000);
  auto second = wircam::wirc::packetizeFrame(sceneFrames()[1], 2, 1000);
  auto third = wircam::wirc::packetizeFrame(sceneFrames()[2], 3, 1000);
  for (const auto& p : first) push(p);
  EXPECT_EQ(pullBytes(), sceneFrames()[0]);
  for (size_t i = 0; i + 1 < second.size(); ++i) push(second[i]);  // last packet lost
  for (const auto& p : third) push(p);
  GstBuffer* buffer = nullptr;
  EXPECT_EQ(pullBytes(&buffer), sceneFrames()[2]);
  EXPECT_TRUE(GST_BUFFER_FLAG_IS_SET(buffer, GST_BUFFER_FLAG_DISCONT));
  gst_buffer_unref(buffer);
  EXPECT_TRUE(pullBytes().empty());
  EXPECT_EQ(stat("frames-complete"), 2u);
  EXPECT_EQ(stat("frames-incomplete"), 1u);
}

TEST_F(WircDepayTest, CountsGarbageAndKeepsGoing) {
  push({1, 2, 3});
  push(std::vector<uint8_t>(40, 0xAB));
  for (const auto& p : wircam::wirc::packetizeFrame(sceneFrames()[3], 9, 64512)) push(p);
  EXPECT_EQ(pullBytes(), sceneFrames()[3]);
  EXPECT_EQ(stat("packets-invalid"), 2u);
}

// frame-timeout counts the datagrams' time, not the test's: a frame whose
// last packet is still missing 150 ms of stream time later is held; 250 ms
// later it is given up, though both run in microseconds here.
TEST_F(WircDepayTest, TheFrameTimeoutRunsOnTheDatagramsTimestamps) {
  g_object_set(harness_->element, "frame-timeout", 200u, nullptr);
  auto first = wircam::wirc::packetizeFrame(sceneFrames()[0], 1, 1000);
  for (size_t i = 0; i + 1 < first.size(); ++i) push(first[i]);  // last packet still to come
  GstClockTime started = GST_SECOND;
  wait(150 * GST_MSECOND);
  push({1, 2, 3});  // anything that arrives: the depayloader looks at the time then
  EXPECT_EQ(stat("frames-timed-out"), 0u);
  push(first.back());
  GstBuffer* buffer = nullptr;
  EXPECT_EQ(pullBytes(&buffer), sceneFrames()[0]);
  ASSERT_NE(buffer, nullptr);
  EXPECT_EQ(GST_BUFFER_PTS(buffer), started);  // its first datagram's time
  gst_buffer_unref(buffer);

  auto second = wircam::wirc::packetizeFrame(sceneFrames()[1], 2, 1000);
  for (size_t i = 0; i + 1 < second.size(); ++i) push(second[i]);
  wait(250 * GST_MSECOND);
  push({1, 2, 3});
  EXPECT_EQ(stat("frames-timed-out"), 1u);
  EXPECT_TRUE(pullBytes().empty());
}

// The counters come as wirc-stats element messages, as wircsrc's do: one
// each stats-interval of the datagrams' time, none before the first.
TEST_F(WircDepayTest, PostsItsCountersAsWircStatsEachStatsInterval) {
  GstBus* bus = gst_bus_new();
  gst_element_set_bus(harness_->element, bus);
  g_object_set(harness_->element, "stats-interval", 500u, nullptr);
  auto frame = wircam::wirc::packetizeFrame(sceneFrames()[2], 1, 64512);
  for (const auto& p : frame) push(p);
  EXPECT_EQ(gst_bus_pop(bus), nullptr);  // the first interval has not passed
  wait(600 * GST_MSECOND);
  push({1, 2, 3});
  GstMessage* message = gst_bus_pop_filtered(bus, GST_MESSAGE_ELEMENT);
  ASSERT_NE(message, nullptr);
  const GstStructure* stats = gst_message_get_structure(message);
  EXPECT_TRUE(gst_structure_has_name(stats, "wirc-stats"));
  auto read = wircam::bus::Stats::read(stats);
  EXPECT_EQ(read.framesComplete, 1u);
  gst_message_unref(message);
  push({1, 2, 3});  // within the next interval: nothing more
  EXPECT_EQ(gst_bus_pop(bus), nullptr);
  gst_element_set_bus(harness_->element, nullptr);
  gst_object_unref(bus);
}

}  // namespace
