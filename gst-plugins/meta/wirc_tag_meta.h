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

/* GStreamer's registration, for C; introspection reads the functions below. */
#ifndef __GI_SCANNER__
GType wirc_tag_meta_api_get_type(void);
#define WIRC_TAG_META_API_TYPE (wirc_tag_meta_api_get_type())
const GstMetaInfo* wirc_tag_meta_get_info(void);

WircTagMeta* gst_buffer_add_wirc_tag_meta(GstBuffer* buffer, guint width, guint height);
#define gst_buffer_get_wirc_tag_meta(b) \
  ((WircTagMeta*)gst_buffer_get_meta((b), WIRC_TAG_META_API_TYPE))
#endif

/**
 * wirc_buffer_get_tag_meta:
 * @buffer: a video buffer that passed apriltagdetect
 *
 * Returns: (transfer none) (nullable): the tags found in @buffer, or %NULL
 */
WircTagMeta* wirc_buffer_get_tag_meta(GstBuffer* buffer);

/**
 * wirc_tag_meta_get_n_tags:
 * @meta: the tags of a frame
 *
 * Returns: how many tags were found
 */
guint wirc_tag_meta_get_n_tags(const WircTagMeta* meta);

/**
 * wirc_tag_meta_get_tag:
 * @meta: the tags of a frame
 * @index: 0 .. n_tags - 1
 *
 * Returns: (transfer none) (nullable): the tag, or %NULL past the last one
 */
WircTag* wirc_tag_meta_get_tag(const WircTagMeta* meta, guint index);

/**
 * wirc_tag_get_family:
 * @tag: a tag
 *
 * Returns: (transfer none): its family, e.g. "tag36h11"
 */
const gchar* wirc_tag_get_family(const WircTag* tag);

/**
 * wirc_tag_get_corner:
 * @tag: a tag
 * @index: 0..3, in the detector's order
 * @x: (out): the corner's x, in pixels of the frame
 * @y: (out): the corner's y
 *
 * Returns: %FALSE when @index is not 0..3
 */
gboolean wirc_tag_get_corner(const WircTag* tag, guint index, gdouble* x, gdouble* y);

G_END_DECLS
