/**
 * SECTION:element-tagoverlay
 *
 * Draws what apriltagdetect found (the WircTagMeta of each frame) for viewing
 * and recording: each tag's outline, its id, and, for the control target
 * (`target-id`, or the largest tag when -1), a thicker outline and a line
 * from the image centre to the tag, the error wirccontrol steers away; and
 * each Marvelmind beacon's position (the WircPositionMeta marvelmindpositions
 * joins to the frame) as a line of text in the bottom left corner.
 * Works in place on RGB, BGRx and I420.
 *
 * ## Example launch line
 * |[
 * gst-launch-1.0 wircsrc host=127.0.0.1 ! tjpegdec ! video/x-raw,format=I420 ! apriltagdetect ! tagoverlay ! videoconvert ! autovideosink
 * ]|
 */
#include "gsttagoverlay.h"

#include <gst/video/video.h>

#include <cmath>
#include <cstdio>
#include <opencv2/imgproc.hpp>
#include <string>

#include "wirc_position_meta.h"
#include "wirc_tag_meta.h"

GST_DEBUG_CATEGORY_STATIC(tag_overlay_debug);
#define GST_CAT_DEFAULT tag_overlay_debug

#define DEFAULT_TARGET_ID -1
#define DEFAULT_SHOW_IDS TRUE

enum { PROP_0, PROP_TARGET_ID, PROP_SHOW_IDS };

struct _GstTagOverlay {
  GstVideoFilter parent;
  gint targetId;  // guarded by the object lock
  gboolean showIds;
};

G_DEFINE_TYPE(GstTagOverlay, gst_tag_overlay, GST_TYPE_VIDEO_FILTER)

#define CAPS GST_VIDEO_CAPS_MAKE("{ I420, RGB, BGRx }")
static GstStaticPadTemplate sink_template =
    GST_STATIC_PAD_TEMPLATE("sink", GST_PAD_SINK, GST_PAD_ALWAYS, GST_STATIC_CAPS(CAPS));
static GstStaticPadTemplate src_template =
    GST_STATIC_PAD_TEMPLATE("src", GST_PAD_SRC, GST_PAD_ALWAYS, GST_STATIC_CAPS(CAPS));

namespace {

struct Colour {
  uint8_t r, g, b;
};
constexpr Colour kTagColour{40, 220, 60};
constexpr Colour kTargetColour{255, 60, 40};
constexpr Colour kPositionColour{255, 230, 80};

// One plane to draw on, with the colour in that plane's terms and the scale
// from frame to plane coordinates (chroma planes of I420 are half size).
struct Canvas {
  cv::Mat plane;
  cv::Scalar colour;
  double scale;
};

std::vector<Canvas> canvases(GstVideoFrame* frame, Colour c) {
  auto plane = [&](int i, int type) {
    return cv::Mat(GST_VIDEO_FRAME_COMP_HEIGHT(frame, i), GST_VIDEO_FRAME_COMP_WIDTH(frame, i),
                   type, GST_VIDEO_FRAME_PLANE_DATA(frame, i),
                   GST_VIDEO_FRAME_PLANE_STRIDE(frame, i));
  };
  switch (GST_VIDEO_FRAME_FORMAT(frame)) {
    case GST_VIDEO_FORMAT_RGB:
      return {{plane(0, CV_8UC3), cv::Scalar(c.r, c.g, c.b), 1.0}};
    case GST_VIDEO_FORMAT_BGRx:
      return {{plane(0, CV_8UC4), cv::Scalar(c.b, c.g, c.r, 255), 1.0}};
    default: {  // I420: BT.601 limited range
      double y = 16 + 0.257 * c.r + 0.504 * c.g + 0.098 * c.b;
      double u = 128 - 0.148 * c.r - 0.291 * c.g + 0.439 * c.b;
      double v = 128 + 0.439 * c.r - 0.368 * c.g - 0.071 * c.b;
      return {{plane(0, CV_8UC1), cv::Scalar(y), 1.0},
              {plane(1, CV_8UC1), cv::Scalar(u), 0.5},
              {plane(2, CV_8UC1), cv::Scalar(v), 0.5}};
    }
  }
}

void drawTag(GstVideoFrame* frame, const WircTag& tag, bool target, bool showId, double scaleX,
             double scaleY) {
  int width = GST_VIDEO_FRAME_WIDTH(frame), height = GST_VIDEO_FRAME_HEIGHT(frame);
  for (auto& canvas : canvases(frame, target ? kTargetColour : kTagColour)) {
    auto at = [&](double x, double y) {
      return cv::Point(static_cast<int>(std::lround(x * scaleX * canvas.scale)),
                       static_cast<int>(std::lround(y * scaleY * canvas.scale)));
    };
    int thickness = std::max(1, static_cast<int>(std::lround((target ? 3 : 2) * canvas.scale)));
    for (int i = 0; i < 4; ++i) {
      int j = (i + 1) % 4;
      cv::line(canvas.plane, at(tag.corners[2 * i], tag.corners[2 * i + 1]),
               at(tag.corners[2 * j], tag.corners[2 * j + 1]), canvas.colour, thickness,
               cv::LINE_AA);
    }
    if (target)
      cv::line(canvas.plane, at(width / 2.0, height / 2.0), at(tag.cx, tag.cy), canvas.colour, 1,
               cv::LINE_AA);
    if (showId) {
      cv::putText(canvas.plane, std::to_string(tag.id), at(tag.cx + 4, tag.cy - 4),
                  cv::FONT_HERSHEY_SIMPLEX, 0.5 * canvas.scale * std::max(1.0, width / 640.0),
                  canvas.colour, thickness, cv::LINE_AA);
    }
  }
}

// Each beacon's position (marvelmindpositions' WircPositionMeta) as a line
// of text in the bottom left corner, the first beacon lowest.
void drawPositions(GstVideoFrame* frame) {
  int width = GST_VIDEO_FRAME_WIDTH(frame), height = GST_VIDEO_FRAME_HEIGHT(frame);
  double fontScale = 0.45 * std::max(1.0, width / 640.0);
  int lineHeight = static_cast<int>(22 * std::max(1.0, width / 640.0));
  int row = 0;
  gpointer state = nullptr;
  while (GstMeta* found =
             gst_buffer_iterate_meta_filtered(frame->buffer, &state, WIRC_POSITION_META_API_TYPE)) {
    auto* position = reinterpret_cast<WircPositionMeta*>(found);
    char text[96];
    std::snprintf(text, sizeof text, "beacon %u: %.2f, %.2f, %.2f m", position->beacon, position->x,
                  position->y, position->z);
    int baseline = height - 8 - lineHeight * row++;
    if (baseline < lineHeight) break;
    for (auto& canvas : canvases(frame, kPositionColour)) {
      auto at =
          cv::Point(static_cast<int>(8 * canvas.scale), static_cast<int>(baseline * canvas.scale));
      cv::putText(canvas.plane, text, at, cv::FONT_HERSHEY_SIMPLEX, fontScale * canvas.scale,
                  canvas.colour, std::max(1, static_cast<int>(std::lround(canvas.scale))),
                  cv::LINE_AA);
    }
  }
}

}  // namespace

static GstFlowReturn gst_tag_overlay_transform_frame_ip(GstVideoFilter* filter,
                                                        GstVideoFrame* frame) {
  auto* self = GST_TAG_OVERLAY(filter);
  drawPositions(frame);
  WircTagMeta* meta = gst_buffer_get_wirc_tag_meta(frame->buffer);
  if (!meta || meta->tags->len == 0 || meta->width == 0 || meta->height == 0) return GST_FLOW_OK;
  gint targetId;
  gboolean showIds;
  GST_OBJECT_LOCK(self);
  targetId = self->targetId;
  showIds = self->showIds;
  GST_OBJECT_UNLOCK(self);

  // The meta may come from a frame of another size (detection on a scaled copy).
  double scaleX = static_cast<double>(GST_VIDEO_FRAME_WIDTH(frame)) / meta->width;
  double scaleY = static_cast<double>(GST_VIDEO_FRAME_HEIGHT(frame)) / meta->height;
  const WircTag* target = nullptr;
  double targetSize = 0;
  for (guint i = 0; i < meta->tags->len; ++i) {
    const auto& tag = g_array_index(meta->tags, WircTag, i);
    double size = std::hypot(tag.corners[2] - tag.corners[0], tag.corners[3] - tag.corners[1]);
    if ((targetId < 0 || tag.id == targetId) && size > targetSize) {
      target = &tag;
      targetSize = size;
    }
  }
  for (guint i = 0; i < meta->tags->len; ++i) {
    const auto& tag = g_array_index(meta->tags, WircTag, i);
    drawTag(frame, tag, &tag == target, showIds, scaleX, scaleY);
  }
  return GST_FLOW_OK;
}

static void gst_tag_overlay_set_property(GObject* object, guint id, const GValue* value,
                                         GParamSpec* pspec) {
  auto* self = GST_TAG_OVERLAY(object);
  GST_OBJECT_LOCK(self);
  if (id == PROP_TARGET_ID)
    self->targetId = g_value_get_int(value);
  else if (id == PROP_SHOW_IDS)
    self->showIds = g_value_get_boolean(value);
  else
    G_OBJECT_WARN_INVALID_PROPERTY_ID(object, id, pspec);
  GST_OBJECT_UNLOCK(self);
}

static void gst_tag_overlay_get_property(GObject* object, guint id, GValue* value,
                                         GParamSpec* pspec) {
  auto* self = GST_TAG_OVERLAY(object);
  GST_OBJECT_LOCK(self);
  if (id == PROP_TARGET_ID)
    g_value_set_int(value, self->targetId);
  else if (id == PROP_SHOW_IDS)
    g_value_set_boolean(value, self->showIds);
  else
    G_OBJECT_WARN_INVALID_PROPERTY_ID(object, id, pspec);
  GST_OBJECT_UNLOCK(self);
}

static void gst_tag_overlay_init(GstTagOverlay* self) {
  self->targetId = DEFAULT_TARGET_ID;
  self->showIds = DEFAULT_SHOW_IDS;
  gst_base_transform_set_in_place(GST_BASE_TRANSFORM(self), TRUE);
}

static void gst_tag_overlay_class_init(GstTagOverlayClass* klass) {
  auto* gobject = G_OBJECT_CLASS(klass);
  auto* element = GST_ELEMENT_CLASS(klass);
  gobject->set_property = gst_tag_overlay_set_property;
  gobject->get_property = gst_tag_overlay_get_property;
  auto flags = static_cast<GParamFlags>(G_PARAM_READWRITE | G_PARAM_STATIC_STRINGS |
                                        GST_PARAM_MUTABLE_PLAYING);
  g_object_class_install_property(
      gobject, PROP_TARGET_ID,
      g_param_spec_int(
          "target-id", "Target id",
          "Tag drawn as the control target (-1 = the largest), as wirccontrol's target-id", -1,
          65535, DEFAULT_TARGET_ID, flags));
  g_object_class_install_property(
      gobject, PROP_SHOW_IDS,
      g_param_spec_boolean("show-ids", "Show ids", "Write each tag's id beside it",
                           DEFAULT_SHOW_IDS, flags));
  gst_element_class_add_static_pad_template(element, &sink_template);
  gst_element_class_add_static_pad_template(element, &src_template);
  gst_element_class_set_static_metadata(
      element, "AprilTag overlay", "Filter/Effect/Video",
      "Draws the AprilTags found by apriltagdetect, the control target and Marvelmind positions",
      "wircam authors");
  GST_VIDEO_FILTER_CLASS(klass)->transform_frame_ip = gst_tag_overlay_transform_frame_ip;
  GST_DEBUG_CATEGORY_INIT(tag_overlay_debug, "tagoverlay", 0, "AprilTag overlay");
}
