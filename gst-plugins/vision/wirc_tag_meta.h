/* WircTagMeta: the AprilTags apriltagdetect found in a video frame, attached
 * to the frame's buffer. A public API: any element or application can read
 * it with gst_buffer_get_wirc_tag_meta(). Coordinates are in the pixels of
 * the frame the meta is attached to. */
#pragma once

#include <gst/gst.h>

G_BEGIN_DECLS

typedef struct {
  gint id;
  gchar family[24];
  gint hamming;
  gdouble margin;
  gdouble cx, cy;
  gdouble corners[8]; /* x0 y0 x1 y1 x2 y2 x3 y3, in the detector's order */
  gboolean has_pose;
  gdouble x, y, z, yaw; /* camera frame, metres and radians, when has_pose */
} WircTag;

typedef struct {
  GstMeta meta;
  guint width, height; /* size of the frame the coordinates refer to */
  GArray* tags;        /* of WircTag */
} WircTagMeta;

GType wirc_tag_meta_api_get_type(void);
#define WIRC_TAG_META_API_TYPE (wirc_tag_meta_api_get_type())
const GstMetaInfo* wirc_tag_meta_get_info(void);

WircTagMeta* gst_buffer_add_wirc_tag_meta(GstBuffer* buffer, guint width, guint height);
#define gst_buffer_get_wirc_tag_meta(b) \
  ((WircTagMeta*)gst_buffer_get_meta((b), WIRC_TAG_META_API_TYPE))

G_END_DECLS
