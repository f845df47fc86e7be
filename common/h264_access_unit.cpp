#include "common/h264_access_unit.h"

#include <cstdint>

namespace wircam {

namespace {

constexpr int kIdrSlice = 5;

int typeOf(uint8_t header) { return header & 0x1f; }

bool idrAfterLengths(std::string_view unit, size_t lengthSize) {
  bool idr = false;
  for (size_t at = 0; at < unit.size();) {
    if (unit.size() - at < lengthSize) return false;
    size_t length = 0;
    for (size_t i = 0; i < lengthSize; ++i)
      length = length << 8 | static_cast<uint8_t>(unit[at + i]);
    at += lengthSize;
    if (length == 0 || length > unit.size() - at) return false;
    idr |= typeOf(static_cast<uint8_t>(unit[at])) == kIdrSlice;
    at += length;
  }
  return idr;
}

bool idrAfterStartCodes(std::string_view unit) {
  // Each NAL unit's header is the byte after a 00 00 01 (a four-byte start
  // code ends the same way).
  for (size_t at = 0; at + 3 < unit.size(); ++at)
    if (unit[at] == 0 && unit[at + 1] == 0 && unit[at + 2] == 1 &&
        typeOf(static_cast<uint8_t>(unit[at + 3])) == kIdrSlice)
      return true;
  return false;
}

}  // namespace

bool startsDecoding(std::string_view accessUnit, H264Framing framing) {
  if (framing.lengthSize == 0) return idrAfterStartCodes(accessUnit);
  if (framing.lengthSize != 1 && framing.lengthSize != 2 && framing.lengthSize != 4) return false;
  return idrAfterLengths(accessUnit, framing.lengthSize);
}

}  // namespace wircam
