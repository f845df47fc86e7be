#include "wirc/jpeg_info.h"

#include "common/byte_reader.h"

namespace wircam::wirc {

std::optional<JpegInfo> readJpegInfo(std::span<const uint8_t> jpeg) {
  ByteReader reader(jpeg);
  if (reader.readU16Be() != 0xFFD8) return std::nullopt;
  while (reader.ok() && reader.remaining() > 0) {
    if (reader.readU8() != 0xFF) return std::nullopt;
    uint8_t marker = reader.readU8();
    while (marker == 0xFF && reader.ok()) marker = reader.readU8();  // fill bytes
    if (marker == 0xD8 || marker == 0x01 || (marker >= 0xD0 && marker <= 0xD7)) continue;
    if (marker == 0xD9 || marker == 0xDA) return std::nullopt;  // EOI or scan before any SOF
    uint16_t length = reader.readU16Be();
    if (length < 2) return std::nullopt;
    // SOF0..SOF15, except DHT (C4), JPG (C8) and DAC (CC).
    bool startOfFrame =
        marker >= 0xC0 && marker <= 0xCF && marker != 0xC4 && marker != 0xC8 && marker != 0xCC;
    if (startOfFrame) {
      ByteReader segment(reader.readBytes(length - 2u));
      segment.readU8();  // precision
      JpegInfo info;
      info.height = segment.readU16Be();
      info.width = segment.readU16Be();
      info.components = segment.readU8();
      if (!segment.ok() || info.width == 0 || info.height == 0) return std::nullopt;
      return info;
    }
    reader.readBytes(length - 2u);
  }
  return std::nullopt;
}

}  // namespace wircam::wirc
