// Whether a GStreamer buffer of video/x-h264 is a place a decoder can start
// (common/h264_access_unit.h), its framing read off its caps: "avc" with the
// length size its codec_data gives, or "byte-stream". Internal, as
// gst_scoped.h.
#pragma once

#include <gst/gst.h>

#include "common/h264_access_unit.h"
#include "gst_scoped.h"

namespace wircam::gst {

inline H264Framing h264FramingOf(GstCaps* caps) {
  const GstStructure* structure = caps ? gst_caps_get_structure(caps, 0) : nullptr;
  const char* format = structure ? gst_structure_get_string(structure, "stream-format") : nullptr;
  if (g_strcmp0(format, "byte-stream") == 0) return H264Framing::byteStream();
  // An AVCDecoderConfigurationRecord's fifth byte: lengthSizeMinusOne.
  const GValue* record = structure ? gst_structure_get_value(structure, "codec_data") : nullptr;
  if (record && GST_VALUE_HOLDS_BUFFER(record)) {
    guint8 byte = 0;
    if (gst_buffer_extract(gst_value_get_buffer(record), 4, &byte, 1) == 1)
      return {static_cast<size_t>((byte & 3) + 1)};
  }
  return {};
}

inline bool h264StartsDecoding(GstBuffer* buffer, GstCaps* caps) {
  ScopedBufferMap map(buffer, GST_MAP_READ);
  return map && startsDecoding(map.view(), h264FramingOf(caps));
}

}  // namespace wircam::gst
