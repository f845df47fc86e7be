/**
 * SECTION:element-apriltagdetect
 *
 * Finds AprilTags in the luma of GRAY8, I420 or NV12 frames, in place. Each
 * buffer leaves with a WircTagMeta listing the tags, and an `apriltag`
 * element message goes to the bus per frame: `timestamp` (PTS), `frame`
 * (counter) and `detections`, a list of `tag` structures with `id`,
 * `family`, `hamming`, `margin`, `cx`, `cy`, `corners` (x0 y0 ... x3 y3) and,
 * when `tag-size` and `fx`/`fy` are set, `x`, `y`, `z` (metres, camera frame)
 * and `yaw`. Coordinates are in the input frame's pixels whatever the
 * decimation. With `roi-tracking`, tags already found are searched for
 * only in windows around where they are heading.
 *
 * ## Example launch line
 * |[
 * gst-launch-1.0 -m wircsrc host=127.0.0.1 ! tjpegdec ! apriltagdetect family=tag36h11 ! fakesink
 * ]|
 */
#include "gstapriltagdetect.h"

#include <gst/video/video.h>

#include <algorithm>
#include <mutex>
#include <optional>
#include <string>

#include "tag_tracker.h"
#include "wirc_bus_messages.h"
#include "wirc_tag_meta.h"

GST_DEBUG_CATEGORY_STATIC(apriltag_detect_debug);
#define GST_CAT_DEFAULT apriltag_detect_debug

namespace {

using namespace wircam;

#define DEFAULT_FAMILY "tag36h11"
#define DEFAULT_QUAD_DECIMATE 1.0f
#define DEFAULT_QUAD_SIGMA 0.0f
#define DEFAULT_THREADS 1
#define DEFAULT_REFINE_EDGES TRUE
#define DEFAULT_DECODE_SHARPENING 0.25
#define DEFAULT_MAX_HAMMING 1
#define DEFAULT_MIN_MARGIN 0.0
#define DEFAULT_TAG_SIZE 0.0
#define DEFAULT_ROI_TRACKING FALSE
#define DEFAULT_FULL_FRAME_INTERVAL 10

enum {
  PROP_0,
  PROP_FAMILY,
  PROP_QUAD_DECIMATE,
  PROP_QUAD_SIGMA,
  PROP_THREADS,
  PROP_REFINE_EDGES,
  PROP_DECODE_SHARPENING,
  PROP_MAX_HAMMING,
  PROP_MIN_MARGIN,
  PROP_TAG_SIZE,
  PROP_FX,
  PROP_FY,
  PROP_CX,
  PROP_CY,
  PROP_ROI_TRACKING,
  PROP_FULL_FRAME_INTERVAL,
};

// The AprilTag 3 families as a GEnum, so gst-inspect-1.0 lists them and a
// misspelt one is refused where it is set.
GType familyType() {
  static GType type = [] {
    const auto& names = vision::TagFamily::names();
    // Registered once for the life of the process, as GLib wants.
    auto* values = new GEnumValue[names.size() + 1]();
    for (size_t i = 0; i < names.size(); ++i)
      values[i] = {static_cast<gint>(i), names[i].c_str(), names[i].c_str()};
    return g_enum_register_static("GstApriltagFamily", values);
  }();
  return type;
}

gint familyIndex(const std::string& name) {
  const auto& names = vision::TagFamily::names();
  return static_cast<gint>(std::find(names.begin(), names.end(), name) - names.begin());
}

struct ApriltagDetectState {
  // Guarded by the object lock; a change makes the detector be rebuilt.
  vision::DetectorOptions options;
  double tagSize = DEFAULT_TAG_SIZE, fx = 0, fy = 0, cx = 0, cy = 0;
  gboolean roiTracking = DEFAULT_ROI_TRACKING;
  gint fullFrameInterval = DEFAULT_FULL_FRAME_INTERVAL;
  bool dirty = true;

  // Without roi-tracking the tracker searches the whole frame every time.
  std::optional<vision::TagTracker> detector;  // streaming thread only
  guint64 frames = 0;
};

}  // namespace

struct _GstApriltagDetect {
  GstVideoFilter parent;
  ApriltagDetectState* state;
};

G_DEFINE_TYPE(GstApriltagDetect, gst_apriltag_detect, GST_TYPE_VIDEO_FILTER)

#define CAPS GST_VIDEO_CAPS_MAKE("{ GRAY8, I420, NV12 }")
static GstStaticPadTemplate sink_template =
    GST_STATIC_PAD_TEMPLATE("sink", GST_PAD_SINK, GST_PAD_ALWAYS, GST_STATIC_CAPS(CAPS));
static GstStaticPadTemplate src_template =
    GST_STATIC_PAD_TEMPLATE("src", GST_PAD_SRC, GST_PAD_ALWAYS, GST_STATIC_CAPS(CAPS));

// Rebuilds the detector if a property changed; false (with an element error)
// when the options are unusable.
static bool ensure_detector(GstApriltagDetect* self, const GstVideoInfo& info) {
  auto* state = self->state;
  vision::DetectorOptions options;
  vision::TrackerOptions tracking;
  {
    GST_OBJECT_LOCK(self);
    tracking.fullFrameInterval = state->roiTracking ? state->fullFrameInterval : 1;
    if (!state->dirty && state->detector) {
      GST_OBJECT_UNLOCK(self);
      return true;
    }
    options = state->options;
    if (state->tagSize > 0 && state->fx > 0) {
      double fy = state->fy > 0 ? state->fy : state->fx;
      // A principal point of 0 means the image centre.
      double cx = state->cx > 0 ? state->cx : GST_VIDEO_INFO_WIDTH(&info) / 2.0;
      double cy = state->cy > 0 ? state->cy : GST_VIDEO_INFO_HEIGHT(&info) / 2.0;
      options.pose = vision::PoseConfig{state->tagSize, state->fx, fy, cx, cy};
    }
    state->dirty = false;
    GST_OBJECT_UNLOCK(self);
  }
  auto detector = vision::TagTracker::create(options, tracking);
  if (!detector) {
    GST_ELEMENT_ERROR(self, LIBRARY, SETTINGS, ("Invalid apriltagdetect settings"),
                      ("%s", detector.error().c_str()));
    return false;
  }
  state->detector.emplace(std::move(*detector));
  return true;
}

static GValue tag_structure_value(const vision::TagDetection& d) {
  GstStructure* s =
      gst_structure_new("tag", "id", G_TYPE_INT, d.id, "family", G_TYPE_STRING, d.family.c_str(),
                        "hamming", G_TYPE_INT, d.hamming, "margin", G_TYPE_DOUBLE, d.margin, "cx",
                        G_TYPE_DOUBLE, d.center.x, "cy", G_TYPE_DOUBLE, d.center.y, nullptr);
  GValue corners = G_VALUE_INIT;
  gst_value_array_init(&corners, 8);
  for (const auto& c : d.corners) {
    for (double v : {c.x, c.y}) {
      GValue number = G_VALUE_INIT;
      g_value_init(&number, G_TYPE_DOUBLE);
      g_value_set_double(&number, v);
      gst_value_array_append_and_take_value(&corners, &number);
    }
  }
  gst_structure_take_value(s, "corners", &corners);
  if (d.pose)
    gst_structure_set(s, "x", G_TYPE_DOUBLE, d.pose->x, "y", G_TYPE_DOUBLE, d.pose->y, "z",
                      G_TYPE_DOUBLE, d.pose->z, "yaw", G_TYPE_DOUBLE, d.pose->yaw, nullptr);
  GValue value = G_VALUE_INIT;
  g_value_init(&value, GST_TYPE_STRUCTURE);
  gst_value_set_structure(&value, s);
  gst_structure_free(s);
  return value;
}

static GstFlowReturn gst_apriltag_detect_transform_frame_ip(GstVideoFilter* filter,
                                                            GstVideoFrame* frame) {
  auto* self = GST_APRILTAG_DETECT(filter);
  auto* state = self->state;
  if (!ensure_detector(self, frame->info)) return GST_FLOW_ERROR;

  // Plane 0 is the luma in every accepted format.
  vision::GrayView luma{static_cast<const uint8_t*>(GST_VIDEO_FRAME_PLANE_DATA(frame, 0)),
                        GST_VIDEO_FRAME_WIDTH(frame), GST_VIDEO_FRAME_HEIGHT(frame),
                        GST_VIDEO_FRAME_PLANE_STRIDE(frame, 0)};
  auto detections = state->detector->detect(luma);

  WircTagMeta* meta = gst_buffer_add_wirc_tag_meta(frame->buffer, luma.width, luma.height);
  GValue list = G_VALUE_INIT;
  gst_value_list_init(&list, detections.size());
  for (const auto& d : detections) {
    WircTag tag{};
    tag.id = d.id;
    g_strlcpy(tag.family, d.family.c_str(), sizeof tag.family);
    tag.hamming = d.hamming;
    tag.margin = d.margin;
    tag.cx = d.center.x;
    tag.cy = d.center.y;
    for (size_t i = 0; i < 4; ++i) {
      tag.corners[2 * i] = d.corners[i].x;
      tag.corners[2 * i + 1] = d.corners[i].y;
    }
    if (d.pose) {
      tag.has_pose = TRUE;
      tag.x = d.pose->x;
      tag.y = d.pose->y;
      tag.z = d.pose->z;
      tag.yaw = d.pose->yaw;
    }
    g_array_append_val(meta->tags, tag);
    GValue value = tag_structure_value(d);
    gst_value_list_append_and_take_value(&list, &value);
  }

  GstStructure* message = gst_structure_new(wircam::bus::AprilTags::kName, "timestamp",
                                            G_TYPE_UINT64, GST_BUFFER_PTS(frame->buffer), "frame",
                                            G_TYPE_UINT64, state->frames++, nullptr);
  gst_structure_take_value(message, "detections", &list);
  gst_element_post_message(GST_ELEMENT(self), gst_message_new_element(GST_OBJECT(self), message));
  GST_LOG_OBJECT(self, "%zu tags", detections.size());
  return GST_FLOW_OK;
}

static gboolean gst_apriltag_detect_start(GstBaseTransform* transform) {
  GST_APRILTAG_DETECT(transform)->state->frames = 0;
  return TRUE;
}

static void gst_apriltag_detect_set_property(GObject* object, guint id, const GValue* value,
                                             GParamSpec* pspec) {
  auto* self = GST_APRILTAG_DETECT(object);
  auto* state = self->state;
  GST_OBJECT_LOCK(self);
  auto& o = state->options;
  switch (id) {
    case PROP_FAMILY:
      o.family = vision::TagFamily::names().at(static_cast<size_t>(g_value_get_enum(value)));
      break;
    case PROP_QUAD_DECIMATE:
      o.quadDecimate = g_value_get_float(value);
      break;
    case PROP_QUAD_SIGMA:
      o.quadSigma = g_value_get_float(value);
      break;
    case PROP_THREADS:
      o.threads = g_value_get_int(value);
      break;
    case PROP_REFINE_EDGES:
      o.refineEdges = g_value_get_boolean(value);
      break;
    case PROP_DECODE_SHARPENING:
      o.decodeSharpening = g_value_get_double(value);
      break;
    case PROP_MAX_HAMMING:
      o.maxHamming = g_value_get_int(value);
      break;
    case PROP_MIN_MARGIN:
      o.minMargin = g_value_get_double(value);
      break;
    case PROP_TAG_SIZE:
      state->tagSize = g_value_get_double(value);
      break;
    case PROP_FX:
      state->fx = g_value_get_double(value);
      break;
    case PROP_FY:
      state->fy = g_value_get_double(value);
      break;
    case PROP_CX:
      state->cx = g_value_get_double(value);
      break;
    case PROP_CY:
      state->cy = g_value_get_double(value);
      break;
    case PROP_ROI_TRACKING:
      state->roiTracking = g_value_get_boolean(value);
      break;
    case PROP_FULL_FRAME_INTERVAL:
      state->fullFrameInterval = g_value_get_int(value);
      break;
    default:
      G_OBJECT_WARN_INVALID_PROPERTY_ID(object, id, pspec);
      break;
  }
  state->dirty = true;
  GST_OBJECT_UNLOCK(self);
}

static void gst_apriltag_detect_get_property(GObject* object, guint id, GValue* value,
                                             GParamSpec* pspec) {
  auto* self = GST_APRILTAG_DETECT(object);
  auto* state = self->state;
  GST_OBJECT_LOCK(self);
  const auto& o = state->options;
  switch (id) {
    case PROP_FAMILY:
      g_value_set_enum(value, familyIndex(o.family));
      break;
    case PROP_QUAD_DECIMATE:
      g_value_set_float(value, o.quadDecimate);
      break;
    case PROP_QUAD_SIGMA:
      g_value_set_float(value, o.quadSigma);
      break;
    case PROP_THREADS:
      g_value_set_int(value, o.threads);
      break;
    case PROP_REFINE_EDGES:
      g_value_set_boolean(value, o.refineEdges);
      break;
    case PROP_DECODE_SHARPENING:
      g_value_set_double(value, o.decodeSharpening);
      break;
    case PROP_MAX_HAMMING:
      g_value_set_int(value, o.maxHamming);
      break;
    case PROP_MIN_MARGIN:
      g_value_set_double(value, o.minMargin);
      break;
    case PROP_TAG_SIZE:
      g_value_set_double(value, state->tagSize);
      break;
    case PROP_FX:
      g_value_set_double(value, state->fx);
      break;
    case PROP_FY:
      g_value_set_double(value, state->fy);
      break;
    case PROP_CX:
      g_value_set_double(value, state->cx);
      break;
    case PROP_CY:
      g_value_set_double(value, state->cy);
      break;
    case PROP_ROI_TRACKING:
      g_value_set_boolean(value, state->roiTracking);
      break;
    case PROP_FULL_FRAME_INTERVAL:
      g_value_set_int(value, state->fullFrameInterval);
      break;
    default:
      G_OBJECT_WARN_INVALID_PROPERTY_ID(object, id, pspec);
      break;
  }
  GST_OBJECT_UNLOCK(self);
}

static void gst_apriltag_detect_finalize(GObject* object) {
  delete GST_APRILTAG_DETECT(object)->state;
  G_OBJECT_CLASS(gst_apriltag_detect_parent_class)->finalize(object);
}

static void gst_apriltag_detect_init(GstApriltagDetect* self) {
  self->state = new ApriltagDetectState();
  // The element's defaults, where they differ from the library's.
  self->state->options.quadDecimate = DEFAULT_QUAD_DECIMATE;
  gst_base_transform_set_in_place(GST_BASE_TRANSFORM(self), TRUE);
}

static void gst_apriltag_detect_class_init(GstApriltagDetectClass* klass) {
  auto* gobject = G_OBJECT_CLASS(klass);
  auto* element = GST_ELEMENT_CLASS(klass);
  gobject->set_property = gst_apriltag_detect_set_property;
  gobject->get_property = gst_apriltag_detect_get_property;
  gobject->finalize = gst_apriltag_detect_finalize;
  auto flags = static_cast<GParamFlags>(G_PARAM_READWRITE | G_PARAM_STATIC_STRINGS |
                                        GST_PARAM_MUTABLE_PLAYING);

  g_object_class_install_property(
      gobject, PROP_FAMILY,
      g_param_spec_enum("family", "Family", "AprilTag family of the printed tags", familyType(),
                        familyIndex(DEFAULT_FAMILY), flags));
  gst_type_mark_as_plugin_api(familyType(), GstPluginAPIFlags(0));
  g_object_class_install_property(
      gobject, PROP_QUAD_DECIMATE,
      g_param_spec_float("quad-decimate", "Quad decimate",
                         "Find quads on an image this many times smaller (faster; corners are "
                         "still refined at full size). 1 by default: at CIF, 2 (the library's "
                         "default) misses the tag in a fifth of the frames where 1 finds it in "
                         "95 %; raise it for large frames",
                         1, 8, DEFAULT_QUAD_DECIMATE, flags));
  g_object_class_install_property(
      gobject, PROP_QUAD_SIGMA,
      g_param_spec_float("quad-sigma", "Quad sigma",
                         "Gaussian blur before finding quads (0 = none; "
                         "helps on noisy images)",
                         0, 10, DEFAULT_QUAD_SIGMA, flags));
  g_object_class_install_property(gobject, PROP_THREADS,
                                  g_param_spec_int("threads", "Threads", "Detector worker threads",
                                                   1, 64, DEFAULT_THREADS, flags));
  g_object_class_install_property(gobject, PROP_REFINE_EDGES,
                                  g_param_spec_boolean("refine-edges", "Refine edges",
                                                       "Snap quad edges to strong gradients "
                                                       "(more exact corners, little cost)",
                                                       DEFAULT_REFINE_EDGES, flags));
  g_object_class_install_property(gobject, PROP_DECODE_SHARPENING,
                                  g_param_spec_double("decode-sharpening", "Decode sharpening",
                                                      "Sharpening of the decoded bits "
                                                      "(helps small tags)",
                                                      0, 10, DEFAULT_DECODE_SHARPENING, flags));
  g_object_class_install_property(
      gobject, PROP_MAX_HAMMING,
      g_param_spec_int("max-hamming", "Max Hamming",
                       "Most bit errors a detection may have (at most 2: the AprilTag library "
                       "warns that 3 takes prohibitively large amounts of memory, 2.4 GB here)",
                       0, vision::kMaxHamming, DEFAULT_MAX_HAMMING, flags));
  g_object_class_install_property(
      gobject, PROP_MIN_MARGIN,
      g_param_spec_double("min-margin", "Min margin",
                          "Drop detections with a decision margin below this", 0, 1000,
                          DEFAULT_MIN_MARGIN, flags));
  g_object_class_install_property(
      gobject, PROP_TAG_SIZE,
      g_param_spec_double("tag-size", "Tag size",
                          "Edge of the tag's black border in metres; with fx and "
                          "fy it turns on pose (x, y, z, yaw)",
                          0, 100, DEFAULT_TAG_SIZE, flags));
  g_object_class_install_property(
      gobject, PROP_FX,
      g_param_spec_double("fx", "fx", "Focal length in pixels, x (for pose)", 0, 100000, 0, flags));
  g_object_class_install_property(
      gobject, PROP_FY,
      g_param_spec_double("fy", "fy", "Focal length in pixels, y (0 = fx)", 0, 100000, 0, flags));
  g_object_class_install_property(
      gobject, PROP_CX,
      g_param_spec_double("cx", "cx", "Principal point x in pixels (0 = image centre)", 0, 100000,
                          0, flags));
  g_object_class_install_property(
      gobject, PROP_CY,
      g_param_spec_double("cy", "cy", "Principal point y in pixels (0 = image centre)", 0, 100000,
                          0, flags));

  g_object_class_install_property(
      gobject, PROP_ROI_TRACKING,
      g_param_spec_boolean(
          "roi-tracking", "ROI tracking",
          "Once tags are found, search only windows around "
          "where they are heading, at full resolution; search the whole frame every "
          "full-frame-interval frames or when a tag is lost",
          DEFAULT_ROI_TRACKING, flags));
  g_object_class_install_property(
      gobject, PROP_FULL_FRAME_INTERVAL,
      g_param_spec_int("full-frame-interval", "Full-frame interval",
                       "With roi-tracking: frames between "
                       "whole-frame searches (new tags are found at these)",
                       1, 1000, DEFAULT_FULL_FRAME_INTERVAL, flags));
  gst_element_class_add_static_pad_template(element, &sink_template);
  gst_element_class_add_static_pad_template(element, &src_template);
  gst_element_class_set_static_metadata(
      element, "AprilTag detector", "Filter/Analyzer/Video",
      "Finds AprilTags in video frames; attaches WircTagMeta and posts apriltag messages",
      "wircam authors");
  GST_BASE_TRANSFORM_CLASS(klass)->start = gst_apriltag_detect_start;
  GST_VIDEO_FILTER_CLASS(klass)->transform_frame_ip = gst_apriltag_detect_transform_frame_ip;
  GST_DEBUG_CATEGORY_INIT(apriltag_detect_debug, "apriltagdetect", 0, "AprilTag detector");
}
