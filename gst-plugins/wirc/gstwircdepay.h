// wircdepay: WiRC MJPEG datagrams → whole JPEG frames (see gstwircdepay.cpp).
#pragma once

#include <gst/gst.h>

G_BEGIN_DECLS
#define GST_TYPE_WIRC_DEPAY (gst_wirc_depay_get_type())
G_DECLARE_FINAL_TYPE(GstWircDepay, gst_wirc_depay, GST, WIRC_DEPAY, GstElement)
G_END_DECLS
