#include "rcoip/rcoip_messages.h"

#include "common/byte_reader.h"
#include "common/byte_writer.h"

namespace wircam::rcoip {

const char* decodeErrorName(DecodeError error) {
  switch (error) {
    case DecodeError::Empty:
      return "empty";
    case DecodeError::WrongVersion:
      return "wrong version";
    case DecodeError::TooLong:
      return "too long";
    case DecodeError::WrongLength:
      return "wrong length";
  }
  return "unknown";
}

std::vector<uint8_t> encode(const Command& command) {
  std::vector<uint8_t> out;
  out.reserve(1 + command.channels.size());
  ByteWriter writer(out);
  writer.writeU8(kVersion);
  writer.writeBytes(command.channels);
  return out;
}

std::vector<uint8_t> encode(const Reply& reply) {
  std::vector<uint8_t> out;
  ByteWriter writer(out);
  writer.writeU8(kVersion);
  if (reply.rssi) writer.writeU8(*reply.rssi);
  writer.writeU8(reply.battery);
  return out;
}

namespace {

Expected<ByteReader, DecodeError> versioned(std::span<const uint8_t> datagram) {
  if (datagram.empty()) return unexpected(DecodeError::Empty);
  ByteReader reader(datagram);
  if (reader.readU8() != kVersion) return unexpected(DecodeError::WrongVersion);
  return reader;
}

}  // namespace

Expected<Command, DecodeError> decodeCommand(std::span<const uint8_t> datagram) {
  auto reader = versioned(datagram);
  if (!reader) return unexpected(reader.error());
  if (reader->remaining() > kMaxChannels) return unexpected(DecodeError::TooLong);
  auto channels = reader->readRest();
  return Command{{channels.begin(), channels.end()}};
}

Expected<Reply, DecodeError> decodeReply(std::span<const uint8_t> datagram) {
  auto reader = versioned(datagram);
  if (!reader) return unexpected(reader.error());
  Reply reply;
  if (reader->remaining() == 2) {
    reply.rssi = reader->readU8();
    reply.battery = reader->readU8();
  } else if (reader->remaining() == 1) {
    reply.battery = reader->readU8();
  } else {
    return unexpected(DecodeError::WrongLength);
  }
  return reply;
}

}  // namespace wircam::rcoip
