// One UDP datagram as the MJPEG packet decoder sees it: never reads past
// the datagram, and what it accepts is exactly what it would write again.
#include <cstdlib>
#include <cstring>

#include "wirc/mjpeg_packet.h"

using namespace wircam::wirc;

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  std::span<const uint8_t> datagram(data, size);
  auto packet = parseMjpegPacket(datagram);
  if (!packet) return 0;
  const auto& header = packet->header;
  if (packet->payload.size() != header.length) std::abort();
  if (packet->payload.data() < data ||
      packet->payload.data() + packet->payload.size() > data + size)
    std::abort();
  std::vector<uint8_t> written;
  writeMjpegHeader(header, written);
  if (written.size() != kMjpegHeaderSize || std::memcmp(written.data(), data, kMjpegHeaderSize))
    std::abort();
  return 0;
}
