// The bytes of a GstBuffer, for comparing frames in element tests.
#pragma once

#include <gst/gst.h>

#include <cstdint>
#include <vector>

#include "gst_scoped.h"

inline std::vector<uint8_t> bufferBytes(GstBuffer* buffer) {
  wircam::gst::ScopedBufferMap map(buffer, GST_MAP_READ);
  if (!map) return {};
  return {map.data(), map.data() + map.size()};
}
