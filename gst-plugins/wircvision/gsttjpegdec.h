// tjpegdec: JPEG decoder on TurboJPEG (see gsttjpegdec.cpp).
#pragma once

#include <gst/video/gstvideodecoder.h>

G_BEGIN_DECLS
#define GST_TYPE_TJPEG_DEC (gst_tjpeg_dec_get_type())
G_DECLARE_FINAL_TYPE(GstTjpegDec, gst_tjpeg_dec, GST, TJPEG_DEC, GstVideoDecoder)
G_END_DECLS
