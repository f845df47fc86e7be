// tagoverlay: draws the tags found by apriltagdetect (see gsttagoverlay.cpp).
#pragma once

#include <gst/video/gstvideofilter.h>

G_BEGIN_DECLS
#define GST_TYPE_TAG_OVERLAY (gst_tag_overlay_get_type())
G_DECLARE_FINAL_TYPE(GstTagOverlay, gst_tag_overlay, GST, TAG_OVERLAY, GstVideoFilter)
G_END_DECLS
