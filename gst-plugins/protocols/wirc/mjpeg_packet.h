// One UDP datagram of the WiRC MJPEG stream. All fields big-endian:
//
//    0                   1                   2                   3
//    0 1 2 3 4 5 6 7 8 9 0 1 2 3 4 5 6 7 8 9 0 1 2 3 4 5 6 7 8 9 0 1
//   +-----------------------------+-+-------------------------------+
//   | reserved (ignored)     31..17|L|   version = 0x5503     15..0 |
//   +-----------------------------+-+-------------------------------+
//   |                         frame number                          |
//   +---------------------------------------------------------------+
//   |                  offset of the payload in the frame           |
//   +---------------------------------------------------------------+
//   |                 length of the payload in bytes                |
//   +---------------------------------------------------------------+
//   |                     payload (length bytes) ...                |
//
// L (bit 16) marks the last packet of a frame.
#pragma once

#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "common/expected.h"

namespace wircam::wirc {

constexpr uint16_t kMjpegVersion = 0x5503;
constexpr uint32_t kLastPacketFlag = 1u << 16;
constexpr size_t kMjpegHeaderSize = 16;
constexpr size_t kKeepaliveSize = 4;        // a version word alone (protocols/NOTES.md)
constexpr size_t kMaxDatagramSize = 65507;  // largest UDP payload over IPv4
constexpr size_t kDeviceFragmentSize = 64512;

struct MjpegPacketHeader {
  uint32_t version = kMjpegVersion;
  uint32_t frameNumber = 0;
  uint32_t offset = 0;
  uint32_t length = 0;

  bool lastPacket() const { return (version & kLastPacketFlag) != 0; }
};

enum class PacketError {
  Keepalive,   // a 4-byte version-only datagram: not an error, not data
  TooShort,    // shorter than the 16-byte header
  BadVersion,  // low 16 bits of version are not 0x5503
  BadLength,   // length larger than the bytes that follow the header
};

struct MjpegPacket {
  MjpegPacketHeader header;
  std::span<const uint8_t> payload;  // exactly header.length bytes
};

// Parses a datagram; the payload points into it. Bytes beyond `length` are
// ignored (the device never sends them).
Expected<MjpegPacket, PacketError> parseMjpegPacket(std::span<const uint8_t> datagram);

void writeMjpegHeader(const MjpegPacketHeader& header, std::vector<uint8_t>& out);

// Cuts a frame into datagrams of at most fragmentSize payload bytes each, the
// last one flagged: what a WiRC device sends for one JPEG frame.
std::vector<std::vector<uint8_t>> packetizeFrame(std::span<const uint8_t> frame,
                                                 uint32_t frameNumber, size_t fragmentSize);

}  // namespace wircam::wirc
