/* WircPositionMeta: where a Marvelmind beacon was when a video frame was
 * taken, attached to the frame's buffer by marvelmindpositions (one meta per
 * beacon). A public API: read it with gst_buffer_get_wirc_position_meta()
 * (the first) or gst_buffer_iterate_meta_filtered() with
 * WIRC_POSITION_META_API_TYPE (all). It does not depend on the pixels, so
 * scaling and conversion keep it. */
#pragma once

#include <gst/gst.h>

G_BEGIN_DECLS

typedef struct {
  GstMeta meta;
  guint beacon;              /* the beacon's address, 1..254 */
  gdouble x, y, z;           /* metres, in the Marvelmind system's frame */
  gdouble dashboard_time;    /* seconds, the dashboard's clock, when it was measured */
  GstClockTime running_time; /* the same instant on the pipeline's running time */
  /* the frame's running time minus running_time, ns: > 0 when the position
   * is older than the frame, < 0 when it was measured after it */
  gint64 offset;
} WircPositionMeta;

/* GStreamer's registration, for C; introspection reads the functions below. */
#ifndef __GI_SCANNER__
GType wirc_position_meta_api_get_type(void);
#define WIRC_POSITION_META_API_TYPE (wirc_position_meta_api_get_type())
const GstMetaInfo* wirc_position_meta_get_info(void);

WircPositionMeta* gst_buffer_add_wirc_position_meta(GstBuffer* buffer);
#define gst_buffer_get_wirc_position_meta(b) \
  ((WircPositionMeta*)gst_buffer_get_meta((b), WIRC_POSITION_META_API_TYPE))
#endif

/**
 * wirc_buffer_get_n_position_metas:
 * @buffer: a buffer that passed marvelmindpositions
 *
 * Returns: how many beacons' positions @buffer carries
 */
guint wirc_buffer_get_n_position_metas(GstBuffer* buffer);

/**
 * wirc_buffer_get_position_meta:
 * @buffer: a buffer that passed marvelmindpositions
 * @index: 0 .. n - 1
 *
 * Returns: (transfer none) (nullable): the @index-th beacon's position, or %NULL
 */
WircPositionMeta* wirc_buffer_get_position_meta(GstBuffer* buffer, guint index);

G_END_DECLS
