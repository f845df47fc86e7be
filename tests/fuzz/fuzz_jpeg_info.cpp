// The SOF reader on arbitrary "JPEG" bytes: no read past the end, and only
// plausible sizes come out.
#include <cstdlib>

#include "wirc/jpeg_info.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  auto info = wircam::wirc::readJpegInfo({data, size});
  if (info && (info->width < 0 || info->height < 0 || info->components < 0)) std::abort();
  return 0;
}
