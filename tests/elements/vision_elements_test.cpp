// tjpegdec and apriltagdetect in GstHarness, on frames rendered by the
// simulator's scene.
#include <gst/check/gstharness.h>
#include <gst/video/video.h>
#include <gtest/gtest.h>

#include <cmath>
#include <regex>

#include "gst_scoped.h"
#include "pipelines.h"
#include "scene_frames.h"
#include "wirc_position_meta.h"
#include "wirc_tag_meta.h"

namespace {

using wircam::testing::sceneFrames;

GstBuffer* jpegBuffer(const std::vector<uint8_t>& jpeg) {
  GstBuffer* buffer = gst_buffer_new_memdup(jpeg.data(), jpeg.size());
  GST_BUFFER_PTS(buffer) = 0;
  return buffer;
}

// A harness around `description` fed CIF JPEG frames, with `sinkCaps` asked for.
GstHarness* jpegHarness(const char* description, const char* sinkCaps) {
  GstHarness* h = gst_harness_new_parse(description);
  gst_harness_set_src_caps_str(h, "image/jpeg,width=352,height=288,framerate=15/1");
  gst_harness_set_sink_caps_str(h, sinkCaps);
  return h;
}

std::string formatOf(GstHarness* h) {
  GstCaps* caps = gst_pad_get_current_caps(h->sinkpad);
  std::string format = gst_structure_get_string(gst_caps_get_structure(caps, 0), "format");
  gst_caps_unref(caps);
  return format;
}

TEST(TjpegDec, DecodesToTheFormatDownstreamAsksFor) {
  for (const char* format : {"GRAY8", "I420", "RGB", "BGRx"}) {
    std::string sinkCaps = std::string("video/x-raw,format=") + format;
    GstHarness* h = jpegHarness("tjpegdec", sinkCaps.c_str());
    ASSERT_EQ(gst_harness_push(h, jpegBuffer(sceneFrames()[0])), GST_FLOW_OK);
    GstBuffer* out = gst_harness_pull(h);
    ASSERT_NE(out, nullptr);
    EXPECT_EQ(formatOf(h), format);
    GstVideoInfo info;
    GstCaps* caps = gst_pad_get_current_caps(h->sinkpad);
    gst_video_info_from_caps(&info, caps);
    gst_caps_unref(caps);
    EXPECT_EQ(GST_VIDEO_INFO_WIDTH(&info), 352);
    EXPECT_GE(gst_buffer_get_size(out), GST_VIDEO_INFO_SIZE(&info));
    gst_buffer_unref(out);
    gst_harness_teardown(h);
  }
}

TEST(TjpegDec, ScalesWhileDecoding) {
  GstHarness* h = jpegHarness("tjpegdec scale=1/4", "video/x-raw,format=GRAY8");
  ASSERT_EQ(gst_harness_push(h, jpegBuffer(sceneFrames()[0])), GST_FLOW_OK);
  gst_buffer_unref(gst_harness_pull(h));
  GstVideoInfo info;
  GstCaps* caps = gst_pad_get_current_caps(h->sinkpad);
  gst_video_info_from_caps(&info, caps);
  gst_caps_unref(caps);
  EXPECT_EQ(GST_VIDEO_INFO_WIDTH(&info), 88);
  EXPECT_EQ(GST_VIDEO_INFO_HEIGHT(&info), 72);
  gst_harness_teardown(h);
}

TEST(TjpegDec, DropsACorruptFrameAndGoesOn) {
  GstHarness* h = jpegHarness("tjpegdec", "video/x-raw,format=GRAY8");
  auto at = [](std::vector<uint8_t> jpeg, GstClockTime pts) {
    GstBuffer* buffer = jpegBuffer(jpeg);
    GST_BUFFER_PTS(buffer) = pts;
    return buffer;
  };
  std::vector<uint8_t> garbage = {0xFF, 0xD8, 0x00, 0x01, 0x02, 0x03};
  EXPECT_EQ(gst_harness_push(h, at(garbage, 0)), GST_FLOW_OK);
  EXPECT_EQ(gst_harness_push(h, at(sceneFrames()[1], GST_SECOND)), GST_FLOW_OK);
  // And once the stream runs: a frame cut short is dropped too.
  const auto& whole = sceneFrames()[2];
  std::vector<uint8_t> truncated(whole.begin(), whole.begin() + 600);
  EXPECT_EQ(gst_harness_push(h, at(truncated, 2 * GST_SECOND)), GST_FLOW_OK);
  // Cut after its headers, two thirds gone: TurboJPEG decodes it with a
  // warning only, the missing rows grey (it came out so).
  std::vector<uint8_t> third(whole.begin(), whole.begin() + whole.size() / 3);
  EXPECT_EQ(gst_harness_push(h, at(third, 2 * GST_SECOND + 1)), GST_FLOW_OK);
  EXPECT_EQ(gst_harness_push(h, at(whole, 3 * GST_SECOND)), GST_FLOW_OK);
  // Exactly the two whole frames come out, neither corrupt one.
  ASSERT_EQ(gst_harness_buffers_in_queue(h), 2u);
  for (GstClockTime expected : {GST_SECOND, 3 * GST_SECOND}) {
    GstBuffer* out = gst_harness_pull(h);
    EXPECT_EQ(GST_BUFFER_PTS(out), expected);
    gst_buffer_unref(out);
  }
  gst_harness_teardown(h);
}

TEST(ApriltagDetect, AFrameTooSmallForATagPassesWithoutOne) {
  // AprilTag's thresholding crashed the process on a frame 2 pixels high
  // (100x2, 1x1; 64x16 at quad-decimate=8), a stranger's trial.
  for (const char* size : {"width=100,height=2", "width=1,height=1", "width=64,height=16"}) {
    GstHarness* h = gst_harness_new_parse("apriltagdetect quad-decimate=8");
    GstCaps* caps = gst_caps_from_string(
        (std::string("video/x-raw,format=GRAY8,framerate=15/1,") + size).c_str());
    gst_harness_set_src_caps(h, gst_caps_ref(caps));
    GstVideoInfo info;
    gst_video_info_from_caps(&info, caps);
    gst_caps_unref(caps);
    GstBuffer* frame = gst_buffer_new_allocate(nullptr, GST_VIDEO_INFO_SIZE(&info), nullptr);
    gst_buffer_memset(frame, 0, 0x80, GST_VIDEO_INFO_SIZE(&info));
    EXPECT_EQ(gst_harness_push(h, frame), GST_FLOW_OK) << size;
    gst_buffer_unref(gst_harness_pull(h));
    gst_harness_teardown(h);
  }
}

TEST(ApriltagDetect, AttachesTheTagAndPostsAMessage) {
  GstHarness* h = jpegHarness("tjpegdec ! apriltagdetect quad-decimate=1 tag-size=0.16 fx=304.8",
                              "video/x-raw,format=GRAY8");
  GstBus* bus = gst_bus_new();
  gst_element_set_bus(h->element, bus);
  ASSERT_EQ(gst_harness_push(h, jpegBuffer(sceneFrames()[0])), GST_FLOW_OK);
  GstBuffer* out = gst_harness_pull(h);
  WircTagMeta* meta = gst_buffer_get_wirc_tag_meta(out);
  ASSERT_NE(meta, nullptr);
  ASSERT_EQ(meta->tags->len, 1u);
  const WircTag& tag = g_array_index(meta->tags, WircTag, 0);
  EXPECT_EQ(tag.id, 0);
  EXPECT_STREQ(tag.family, "tag36h11");
  EXPECT_NEAR(tag.cx, 176, 30);
  EXPECT_TRUE(tag.has_pose);
  EXPECT_NEAR(tag.z, 1.3, 0.3);  // the scene starts the target 1.2 m ahead
  gst_buffer_unref(out);

  GstMessage* message = gst_bus_pop_filtered(bus, GST_MESSAGE_ELEMENT);
  ASSERT_NE(message, nullptr);
  const GstStructure* s = gst_message_get_structure(message);
  EXPECT_TRUE(gst_structure_has_name(s, "apriltag"));
  const GValue* detections = gst_structure_get_value(s, "detections");
  ASSERT_EQ(gst_value_list_get_size(detections), 1u);
  const GstStructure* first = gst_value_get_structure(gst_value_list_get_value(detections, 0));
  EXPECT_TRUE(gst_structure_has_field(first, "corners"));
  EXPECT_EQ(gst_value_array_get_size(gst_structure_get_value(first, "corners")), 8u);
  gst_message_unref(message);
  gst_element_set_bus(h->element, nullptr);
  gst_object_unref(bus);
  gst_harness_teardown(h);
}

TEST(TagOverlay, OutlinesTheDetectedTag) {
  GstHarness* h = jpegHarness("tjpegdec ! apriltagdetect quad-decimate=1 ! tagoverlay",
                              "video/x-raw,format=I420");
  ASSERT_EQ(gst_harness_push(h, jpegBuffer(sceneFrames()[0])), GST_FLOW_OK);
  GstBuffer* out = gst_harness_pull(h);
  WircTagMeta* meta = gst_buffer_get_wirc_tag_meta(out);
  ASSERT_NE(meta, nullptr);
  ASSERT_EQ(meta->tags->len, 1u);
  const WircTag& tag = g_array_index(meta->tags, WircTag, 0);
  // The target's outline is red: strong V (red chroma) at its first corner,
  // where the tag itself is black or white (V near 128).
  GstVideoInfo info;
  gst_video_info_set_format(&info, GST_VIDEO_FORMAT_I420, 352, 288);
  {
    wircam::gst::ScopedVideoFrameMap frame(&info, out, GST_MAP_READ);
    ASSERT_TRUE(frame);
    int x = static_cast<int>(std::lround(tag.corners[0])) / 2,
        y = static_cast<int>(std::lround(tag.corners[1])) / 2;
    auto* v = static_cast<const uint8_t*>(GST_VIDEO_FRAME_PLANE_DATA(frame.get(), 2));
    EXPECT_GT(v[y * GST_VIDEO_FRAME_PLANE_STRIDE(frame.get(), 2) + x], 180);
  }
  gst_buffer_unref(out);
  gst_harness_teardown(h);
}

TEST(TagOverlay, WritesEachBeaconsPositionInTheBottomLeftCorner) {
  GstHarness* h = gst_harness_new_parse("tagoverlay");
  gst_harness_set_src_caps_str(h, "video/x-raw,format=RGB,width=320,height=240,framerate=15/1");
  auto blackFrame = [] {
    GstBuffer* buffer = gst_buffer_new_allocate(nullptr, 320 * 240 * 3, nullptr);
    gst_buffer_memset(buffer, 0, 0, 320 * 240 * 3);
    return buffer;
  };
  // The text's yellow pixels in the bottom left 200×40.
  auto yellowPixels = [](GstBuffer* buffer) {
    wircam::gst::ScopedBufferMap map(buffer, GST_MAP_READ);
    int count = 0;
    for (int y = 200; y < 240 && map; ++y)
      for (int x = 0; x < 200; ++x) {
        const uint8_t* p = map.data() + (y * 320 + x) * 3;
        if (p[0] > 150 && p[1] > 130 && p[2] < 100) ++count;
      }
    return count;
  };
  GstBuffer* plain = gst_harness_push_and_pull(h, blackFrame());
  EXPECT_EQ(yellowPixels(plain), 0);
  gst_buffer_unref(plain);
  GstBuffer* placed = blackFrame();
  WircPositionMeta* meta = gst_buffer_add_wirc_position_meta(placed);
  meta->beacon = 5;
  meta->x = 1.25;
  GstBuffer* out = gst_harness_push_and_pull(h, placed);
  EXPECT_GT(yellowPixels(out), 50);
  gst_buffer_unref(out);
  gst_harness_teardown(h);
}

TEST(ApriltagDetect, GstInspectListsTheFamiliesAndTheSafeLimits) {
  // As a user sees it: the families are an enum, quad-decimate defaults to
  // what the README recommends, max-hamming stops at 2.
  std::string text = wircam::testing::commandOutput(
      std::string("GST_PLUGIN_PATH=") + WIRCAM_PLUGIN_DIR + " gst-inspect-1.0 apriltagdetect");
  for (const char* family :
       {"tag36h11", "tag25h9", "tag16h5", "tagCircle21h7", "tagStandard41h12", "tagStandard52h13"})
    EXPECT_NE(text.find(std::string(": ") + family), std::string::npos) << family << "\n" << text;
  EXPECT_NE(text.find("Enum \"GstApriltagFamily\" Default: 0, \"tag36h11\""), std::string::npos);
  // quad-decimate: "Float. Range: 1 - 8 Default: 1", gst-inspect pads the numbers.
  EXPECT_TRUE(std::regex_search(text, std::regex("Float\\. Range: +1 - +8 Default: +1 "))) << text;
  EXPECT_NE(text.find("Range: 0 - 2 Default: 1"), std::string::npos) << text;
}

TEST(ApriltagDetect, RefusesAFamilyItDoesNotKnowWhereItIsSet) {
  GError* error = nullptr;
  GstElement* pipeline =
      gst_parse_launch("videotestsrc ! apriltagdetect family=tag99h1 ! fakesink", &error);
  EXPECT_NE(error, nullptr);
  if (error) g_error_free(error);
  if (pipeline) gst_object_unref(pipeline);
}

}  // namespace
