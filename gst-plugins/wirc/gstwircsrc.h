// wircsrc: live MJPEG source from a WiRC device (see gstwircsrc.cpp).
#pragma once

#include <gst/base/gstpushsrc.h>

G_BEGIN_DECLS
#define GST_TYPE_WIRC_SRC (gst_wirc_src_get_type())
G_DECLARE_FINAL_TYPE(GstWircSrc, gst_wirc_src, GST, WIRC_SRC, GstPushSrc)
G_END_DECLS
