// CRC-16/XMODEM (CRC-CCITT, polynomial 0x1021, initial value 0), the
// checksum of every WiRC control message.
#pragma once

#include <cstdint>
#include <span>

namespace wircam::wirc {

uint16_t crc16Xmodem(std::span<const uint8_t> bytes, uint16_t crc = 0);

}  // namespace wircam::wirc
