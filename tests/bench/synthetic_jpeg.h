// JPEG frames for benchmarks: a textured test image, encoded by TurboJPEG the
// way a camera would (baseline, 4:2:0), so sizes match real CIF/720p frames.
#pragma once

#include <cstdint>
#include <vector>

namespace wircam::bench {

std::vector<uint8_t> syntheticJpeg(int width, int height, int seed, int quality = 80);

}  // namespace wircam::bench
