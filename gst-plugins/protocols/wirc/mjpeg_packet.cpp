#include "wirc/mjpeg_packet.h"

#include <algorithm>

#include "common/byte_reader.h"
#include "common/byte_writer.h"

namespace wircam::wirc {

Expected<MjpegPacket, PacketError> parseMjpegPacket(std::span<const uint8_t> datagram) {
  ByteReader reader(datagram);
  MjpegPacket packet;
  packet.header.version = reader.readU32Be();
  if (!reader.ok()) return unexpected(PacketError::TooShort);
  if ((packet.header.version & 0xFFFF) != kMjpegVersion) return unexpected(PacketError::BadVersion);
  if (datagram.size() == kKeepaliveSize) return unexpected(PacketError::Keepalive);
  packet.header.frameNumber = reader.readU32Be();
  packet.header.offset = reader.readU32Be();
  packet.header.length = reader.readU32Be();
  if (!reader.ok()) return unexpected(PacketError::TooShort);
  packet.payload = reader.readBytes(packet.header.length);
  if (!reader.ok()) return unexpected(PacketError::BadLength);
  return packet;
}

void writeMjpegHeader(const MjpegPacketHeader& header, std::vector<uint8_t>& out) {
  ByteWriter writer(out);
  writer.writeU32Be(header.version);
  writer.writeU32Be(header.frameNumber);
  writer.writeU32Be(header.offset);
  writer.writeU32Be(header.length);
}

std::vector<std::vector<uint8_t>> packetizeFrame(std::span<const uint8_t> frame,
                                                 uint32_t frameNumber, size_t fragmentSize) {
  std::vector<std::vector<uint8_t>> packets;
  fragmentSize = std::max<size_t>(fragmentSize, 1);
  size_t offset = 0;
  do {
    size_t length = std::min(fragmentSize, frame.size() - offset);
    bool last = offset + length == frame.size();
    MjpegPacketHeader header;
    header.version = kMjpegVersion | (last ? kLastPacketFlag : 0);
    header.frameNumber = frameNumber;
    header.offset = static_cast<uint32_t>(offset);
    header.length = static_cast<uint32_t>(length);
    std::vector<uint8_t> datagram;
    datagram.reserve(kMjpegHeaderSize + length);
    writeMjpegHeader(header, datagram);
    datagram.insert(datagram.end(), frame.begin() + offset, frame.begin() + offset + length);
    packets.push_back(std::move(datagram));
    offset += length;
  } while (offset < frame.size());
  return packets;
}

}  // namespace wircam::wirc
