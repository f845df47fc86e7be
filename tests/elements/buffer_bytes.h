// The bytes of a GstBuffer, for comparing frames in element tests.
#pragma once

#include <gst/gst.h>

#include <cstdint>
#include <vector>

inline std::vector<uint8_t> bufferBytes(GstBuffer* buffer) {
  GstMapInfo map;
  if (!gst_buffer_map(buffer, &map, GST_MAP_READ)) return {};
  std::vector<uint8_t> bytes(map.data, map.data + map.size);
  gst_buffer_unmap(buffer, &map);
  return bytes;
}
