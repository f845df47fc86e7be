#include "synthetic_jpeg.h"

#include <turbojpeg.h>

#include <memory>
#include <random>
#include <stdexcept>

namespace wircam::bench {

std::vector<uint8_t> syntheticJpeg(int width, int height, int seed, int quality) {
  std::mt19937 random(static_cast<unsigned>(seed));
  std::vector<uint8_t> rgb(static_cast<size_t>(width) * height * 3);
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) {
      uint8_t* p = &rgb[(static_cast<size_t>(y) * width + x) * 3];
      // Gradients and a moving checkerboard, plus noise: realistic entropy.
      bool check = ((x + seed * 4) / 24 + y / 24) % 2;
      p[0] = static_cast<uint8_t>(x * 255 / width);
      p[1] = static_cast<uint8_t>(check ? 200 : 40);
      p[2] = static_cast<uint8_t>(y * 255 / height + random() % 16);
    }
  }
  std::unique_ptr<void, decltype(&tjDestroy)> encoder(tjInitCompress(), tjDestroy);
  unsigned char* jpeg = nullptr;
  unsigned long size = 0;
  if (tjCompress2(encoder.get(), rgb.data(), width, 0, height, TJPF_RGB, &jpeg, &size, TJSAMP_420,
                  quality, TJFLAG_FASTDCT) != 0)
    throw std::runtime_error(tjGetErrorStr2(encoder.get()));
  std::vector<uint8_t> out(jpeg, jpeg + size);
  tjFree(jpeg);
  return out;
}

}  // namespace wircam::bench
