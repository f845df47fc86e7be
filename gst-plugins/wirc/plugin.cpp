// The "wirc" GStreamer plugin: elements that speak the WiRC protocols.
#include <gst/gst.h>

#include "gstmarvelmindpositions.h"
#include "gstwirccontrol.h"
#include "gstwircdepay.h"
#include "gstwircsrc.h"

// wircsrc has a rank so that playbin picks it for wirc:// URIs (it is the
// only handler of that scheme, and autoplugs nothing else).
static gboolean plugin_init(GstPlugin* plugin) {
  return gst_element_register(plugin, "wircsrc", GST_RANK_PRIMARY, GST_TYPE_WIRC_SRC) &&
         gst_element_register(plugin, "wircdepay", GST_RANK_NONE, GST_TYPE_WIRC_DEPAY) &&
         gst_element_register(plugin, "wirccontrol", GST_RANK_NONE, GST_TYPE_WIRC_CONTROL) &&
         gst_element_register(plugin, "marvelmindpositions", GST_RANK_NONE,
                              GST_TYPE_MARVELMIND_POSITIONS);
}

#define PACKAGE "wircam"
GST_PLUGIN_DEFINE(GST_VERSION_MAJOR, GST_VERSION_MINOR, wirc,
                  "WiRC vehicle camera stream, control and telemetry", plugin_init, WIRCAM_VERSION,
                  "MIT/X11", "wircam", "wircam")
