// The "wircvision" GStreamer plugin: decoding and AprilTag detection.
#include <gst/gst.h>

#include "gstapriltagdetect.h"
#include "gsttagoverlay.h"
#include "gsttjpegdec.h"

static gboolean plugin_init(GstPlugin* plugin) {
  return gst_element_register(plugin, "tjpegdec", GST_RANK_NONE, GST_TYPE_TJPEG_DEC) &&
         gst_element_register(plugin, "apriltagdetect", GST_RANK_NONE, GST_TYPE_APRILTAG_DETECT) &&
         gst_element_register(plugin, "tagoverlay", GST_RANK_NONE, GST_TYPE_TAG_OVERLAY);
}

#define PACKAGE "wircam"
GST_PLUGIN_DEFINE(GST_VERSION_MAJOR, GST_VERSION_MINOR, wircvision,
                  "JPEG decoding with libjpeg-turbo and AprilTag detection", plugin_init,
                  WIRCAM_VERSION, "MIT/X11", "wircam", "wircam")
