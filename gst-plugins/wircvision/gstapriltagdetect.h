// apriltagdetect: finds AprilTags in video frames (see gstapriltagdetect.cpp).
#pragma once

#include <gst/video/gstvideofilter.h>

G_BEGIN_DECLS
#define GST_TYPE_APRILTAG_DETECT (gst_apriltag_detect_get_type())
G_DECLARE_FINAL_TYPE(GstApriltagDetect, gst_apriltag_detect, GST, APRILTAG_DETECT, GstVideoFilter)
G_END_DECLS
