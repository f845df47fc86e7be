// marvelmindpositions: Marvelmind beacon positions joined to the video
// (see gstmarvelmindpositions.cpp).
#pragma once

#include <gst/base/gstbasetransform.h>

G_BEGIN_DECLS
#define GST_TYPE_MARVELMIND_POSITIONS (gst_marvelmind_positions_get_type())
G_DECLARE_FINAL_TYPE(GstMarvelmindPositions, gst_marvelmind_positions, GST, MARVELMIND_POSITIONS,
                     GstBaseTransform)
G_END_DECLS
