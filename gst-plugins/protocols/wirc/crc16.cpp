#include "wirc/crc16.h"

#include <array>

namespace wircam::wirc {

namespace {

constexpr std::array<uint16_t, 256> makeTable() {
  std::array<uint16_t, 256> table{};
  for (unsigned byte = 0; byte < 256; ++byte) {
    uint16_t crc = static_cast<uint16_t>(byte << 8);
    for (int bit = 0; bit < 8; ++bit)
      crc = static_cast<uint16_t>(crc & 0x8000 ? (crc << 1) ^ 0x1021 : crc << 1);
    table[byte] = crc;
  }
  return table;
}

constexpr auto kTable = makeTable();

}  // namespace

uint16_t crc16Xmodem(std::span<const uint8_t> bytes, uint16_t crc) {
  for (uint8_t b : bytes) crc = static_cast<uint16_t>(crc << 8) ^ kTable[(crc >> 8) ^ b];
  return crc;
}

}  // namespace wircam::wirc
