#include "marvelmind/marvelmind_messages.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>

#include "common/byte_reader.h"
#include "common/byte_writer.h"

namespace wircam::marvelmind {

namespace {

constexpr size_t kRequestSize = 10;
constexpr uint8_t kRequestReserved = 0x04;
constexpr size_t kHeaderSize = 5;  // addr, type, code, data size
constexpr size_t kCrcSize = 2;

uint8_t dataSizeOf(Resolution resolution) {
  return resolution == Resolution::kCentimetres ? 16 : 22;
}

std::optional<Resolution> resolutionOf(uint16_t code) {
  if (code == static_cast<uint16_t>(Resolution::kCentimetres)) return Resolution::kCentimetres;
  if (code == static_cast<uint16_t>(Resolution::kMillimetres)) return Resolution::kMillimetres;
  return std::nullopt;
}

void appendCrc(std::vector<uint8_t>& frame) {
  uint16_t crc = crc16Modbus(frame);
  ByteWriter(frame).writeU16Le(crc);
}

int16_t centimetres(int32_t mm) {
  double cm = std::round(mm / 10.0);
  return static_cast<int16_t>(std::clamp<double>(cm, std::numeric_limits<int16_t>::min(),
                                                 std::numeric_limits<int16_t>::max()));
}

}  // namespace

double secondsOf(uint32_t timestamp, TimestampUnit unit) {
  return unit == TimestampUnit::kSixtyFourths ? timestamp / 64.0 : timestamp / 1000.0;
}

uint32_t timestampOf(double seconds, TimestampUnit unit) {
  double ticks = seconds * (unit == TimestampUnit::kSixtyFourths ? 64.0 : 1000.0);
  // The dashboard's counter is 32 bits wide and wraps.
  return static_cast<uint32_t>(std::fmod(std::max(ticks, 0.0), 4294967296.0));
}

uint16_t crc16Modbus(std::span<const uint8_t> bytes) {
  uint16_t crc = 0xFFFF;
  for (uint8_t byte : bytes) {
    crc ^= byte;
    for (int bit = 0; bit < 8; ++bit) crc = (crc & 1) ? (crc >> 1) ^ 0xA001 : crc >> 1;
  }
  return crc;
}

const char* decodeErrorName(DecodeError error) {
  switch (error) {
    case DecodeError::kWrongLength:
      return "wrong length";
    case DecodeError::kWrongType:
      return "wrong packet type";
    case DecodeError::kUnknownCode:
      return "unknown code";
    case DecodeError::kWrongDataSize:
      return "wrong data size";
    case DecodeError::kBadCrc:
      return "bad CRC";
  }
  return "unknown";
}

std::vector<uint8_t> encode(const Request& request, bool zeroCrc) {
  std::vector<uint8_t> out;
  out.reserve(kRequestSize);
  ByteWriter writer(out);
  writer.writeU8(request.beacon);
  writer.writeU8(kPacketType);
  writer.writeU16Le(static_cast<uint16_t>(request.resolution));
  writer.writeU8(kRequestReserved);
  writer.writeU16Le(0);
  writer.writeU8(dataSizeOf(request.resolution));
  if (zeroCrc)
    writer.writeU16Le(0);
  else
    appendCrc(out);
  return out;
}

std::vector<uint8_t> encode(const Reply& reply) {
  std::vector<uint8_t> out;
  out.reserve(kHeaderSize + dataSizeOf(reply.resolution) + kCrcSize);
  ByteWriter writer(out);
  writer.writeU8(reply.beacon);
  writer.writeU8(kPacketType);
  writer.writeU16Le(static_cast<uint16_t>(reply.resolution));
  writer.writeU8(dataSizeOf(reply.resolution));
  writer.writeU32Le(reply.timestamp);
  if (reply.resolution == Resolution::kCentimetres) {
    for (int32_t mm : {reply.xMm, reply.yMm, reply.zMm})
      writer.writeU16Le(static_cast<uint16_t>(centimetres(mm)));
    for (int reserved = 0; reserved < 6; ++reserved) writer.writeU8(0);
  } else {
    for (int32_t mm : {reply.xMm, reply.yMm, reply.zMm})
      writer.writeU32Le(static_cast<uint32_t>(mm));
    writer.writeU8(reply.flags);
    writer.writeU8(reply.beacon);
    writer.writeU16Le(reply.angle);
    writer.writeU16Le(0);
  }
  appendCrc(out);
  return out;
}

Expected<Request, DecodeError> decodeRequest(std::span<const uint8_t> datagram) {
  if (datagram.size() != kRequestSize) return unexpected(DecodeError::kWrongLength);
  ByteReader reader(datagram);
  Request request;
  request.beacon = reader.readU8();
  if (reader.readU8() != kPacketType) return unexpected(DecodeError::kWrongType);
  auto resolution = resolutionOf(reader.readU16Le());
  if (!resolution) return unexpected(DecodeError::kUnknownCode);
  request.resolution = *resolution;
  reader.readBytes(3);  // reserved
  if (reader.readU8() != dataSizeOf(request.resolution))
    return unexpected(DecodeError::kWrongDataSize);
  bool zeroCrc = reader.readU16Le() == 0;
  if (!zeroCrc && crc16Modbus(datagram) != 0) return unexpected(DecodeError::kBadCrc);
  return request;
}

Expected<Reply, DecodeError> decodeReply(std::span<const uint8_t> datagram) {
  if (datagram.size() < kHeaderSize + kCrcSize) return unexpected(DecodeError::kWrongLength);
  ByteReader reader(datagram);
  Reply reply;
  reply.beacon = reader.readU8();
  if (reader.readU8() != kPacketType) return unexpected(DecodeError::kWrongType);
  auto resolution = resolutionOf(reader.readU16Le());
  if (!resolution) return unexpected(DecodeError::kUnknownCode);
  reply.resolution = *resolution;
  if (reader.readU8() != dataSizeOf(reply.resolution))
    return unexpected(DecodeError::kWrongDataSize);
  if (datagram.size() != kHeaderSize + dataSizeOf(reply.resolution) + kCrcSize)
    return unexpected(DecodeError::kWrongLength);
  // Checked before any field is believed: a decoy with the right shape but
  // a wrong CRC is not a position.
  if (crc16Modbus(datagram) != 0) return unexpected(DecodeError::kBadCrc);
  reply.timestamp = reader.readU32Le();
  if (reply.resolution == Resolution::kCentimetres) {
    for (int32_t* mm : {&reply.xMm, &reply.yMm, &reply.zMm})
      *mm = 10 * static_cast<int16_t>(reader.readU16Le());
  } else {
    for (int32_t* mm : {&reply.xMm, &reply.yMm, &reply.zMm})
      *mm = static_cast<int32_t>(reader.readU32Le());
    reply.flags = reader.readU8();
    reader.readU8();  // the beacon's address again
    reply.angle = reader.readU16Le();
  }
  return reply;
}

}  // namespace wircam::marvelmind
