// The Marvelmind dashboard's UDP protocol (protocols/marvelmind-dashboard-
// udp.txt, with NOTES.md): a client asks for a beacon's coordinates, the
// dashboard answers with them; or the dashboard pushes the same replies to a
// listening client. Little endian, CRC-16 (Modbus) over every datagram.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "common/expected.h"

namespace wircam::marvelmind {

constexpr uint8_t kPacketType = 0x47;
// Client libraries send requests to 49200 and listen on 49100 (NOTES.md).
constexpr uint16_t kDefaultDashboardPort = 49200;
constexpr uint16_t kDefaultListenPort = 49100;

// Which coordinates a request asks for, and a reply carries (its "code").
enum class Resolution : uint16_t {
  kCentimetres = 0x0001,  // x/y/z int16 cm, the protocol text's
  kMillimetres = 0x0011,  // x/y/z int32 mm, with flags and angle
};

// The text (2016) counts the dashboard's time in 1/64 s; newer dashboards
// in milliseconds.
enum class TimestampUnit { kSixtyFourths, kMilliseconds };
double secondsOf(uint32_t timestamp, TimestampUnit unit);
uint32_t timestampOf(double seconds, TimestampUnit unit);

// CRC-16/MODBUS (reflected 0x8005, initial 0xFFFF): over a whole frame with
// its CRC appended, the result is 0.
uint16_t crc16Modbus(std::span<const uint8_t> bytes);

//   addr | 0x47 | code u16 | 0x04 | 0x0000 | size u8 | CRC u16   (10 bytes)
struct Request {
  uint8_t beacon = 0;
  Resolution resolution = Resolution::kCentimetres;
  bool operator==(const Request&) const = default;
};

//   addr | 0x47 | code u16 | size u8 | data (16 or 22 bytes) | CRC u16
struct Reply {
  uint8_t beacon = 0;
  Resolution resolution = Resolution::kCentimetres;
  uint32_t timestamp = 0;             // the dashboard's, in its TimestampUnit
  int32_t xMm = 0, yMm = 0, zMm = 0;  // cm replies carry multiples of 10
  uint8_t flags = 0;                  // mm replies only
  uint16_t angle = 0;                 // mm replies only
  bool operator==(const Reply&) const = default;
};

enum class DecodeError { kWrongLength, kWrongType, kUnknownCode, kWrongDataSize, kBadCrc };
const char* decodeErrorName(DecodeError error);

// With `zeroCrc` the CRC field is 0, as the vendor's client library sends
// it; dashboards accept either.
std::vector<uint8_t> encode(const Request& request, bool zeroCrc = false);
// cm replies round to the centimetre and clamp to int16.
std::vector<uint8_t> encode(const Reply& reply);
// A request's CRC may be 0; a reply's must check.
Expected<Request, DecodeError> decodeRequest(std::span<const uint8_t> datagram);
Expected<Reply, DecodeError> decodeReply(std::span<const uint8_t> datagram);

}  // namespace wircam::marvelmind
