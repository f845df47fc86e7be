// Reads a JPEG frame's dimensions from its SOF marker, without decoding:
// enough for caps negotiation.
#pragma once

#include <cstdint>
#include <optional>
#include <span>

namespace wircam::wirc {

struct JpegInfo {
  int width = 0;
  int height = 0;
  int components = 0;
};

// nullopt when no start-of-frame marker is found before the scan data.
std::optional<JpegInfo> readJpegInfo(std::span<const uint8_t> jpeg);

}  // namespace wircam::wirc
