// wirccontrol: steers a WiRC vehicle towards an AprilTag (see gstwirccontrol.cpp).
#pragma once

#include <gst/base/gstbasetransform.h>

G_BEGIN_DECLS
#define GST_TYPE_WIRC_CONTROL (gst_wirc_control_get_type())
G_DECLARE_FINAL_TYPE(GstWircControl, gst_wirc_control, GST, WIRC_CONTROL, GstBaseTransform)
G_END_DECLS
