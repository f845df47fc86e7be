// Drives the frame assembler with an arbitrary packet sequence. The input is
// a list of records; most become well-formed packets whose payload comes from
// a known per-frame pattern, so every frame emitted can be checked byte for
// byte; some are raw datagrams, and some carry a corrupted byte.
#include <cstdlib>
#include <set>

#include "common/byte_reader.h"
#include "wirc/frame_assembler.h"

using namespace wircam::wirc;

namespace {

uint8_t patternByte(uint32_t frame, uint32_t offset) {
  if (offset == 0) return 0xFF;
  if (offset == 1) return 0xD8;
  return static_cast<uint8_t>(frame * 131 + offset * 7);
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  FrameAssembler assembler({.maxFrameBytes = 1 << 16,
                            .maxFramesInFlight = 4,
                            .frameTimeout = std::chrono::milliseconds(50),
                            .reorderWindow = 2});
  auto now = FrameAssembler::Clock::time_point{};
  std::set<uint32_t> corrupted;
  std::optional<uint32_t> lastEmitted;

  auto onFrame = [&](AssembledFrame&& frame) {
    const auto& bytes = frame.data;
    if (bytes.size() < 2 || bytes.size() > (1u << 16)) std::abort();
    if (lastEmitted && static_cast<int32_t>(frame.number - *lastEmitted) <= 0 &&
        assembler.stats().senderRestarts == 0)
      std::abort();  // out of order without a restart
    lastEmitted = frame.number;
    if (!corrupted.count(frame.number)) {
      for (uint32_t i = 0; i < bytes.size(); ++i)
        if (bytes.data()[i] != patternByte(frame.number, i)) std::abort();
    }
    assembler.recycle(std::move(frame.data));
  };

  wircam::ByteReader input({data, size});
  std::vector<uint8_t> datagram;
  while (input.remaining() > 0) {
    uint8_t kind = input.readU8();
    now += std::chrono::milliseconds(input.readU8() % 16);
    datagram.clear();
    if (kind % 8 == 0) {  // raw bytes
      auto raw = input.readBytes(std::min<size_t>(input.remaining(), input.readU8()));
      datagram.assign(raw.begin(), raw.end());
      // Raw bytes may form a valid packet with any content: no pattern check.
      if (auto packet = parseMjpegPacket(datagram)) corrupted.insert(packet->header.frameNumber);
    } else {
      uint32_t frame = input.readU8() % 8;
      uint32_t offset = input.readU16Be() % 2048;
      uint32_t length = input.readU16Be() % 1024;
      bool last = kind & 0x10;
      MjpegPacketHeader header{kMjpegVersion | (last ? kLastPacketFlag : 0u), frame, offset,
                               length};
      writeMjpegHeader(header, datagram);
      for (uint32_t i = 0; i < length; ++i) datagram.push_back(patternByte(frame, offset + i));
      if ((kind & 0x60) == 0x60 && length > 0) {
        datagram.back() ^= 0x5A;
        corrupted.insert(frame);
      }
    }
    assembler.pushDatagram(datagram, now, onFrame);
  }
  assembler.expire(now + std::chrono::seconds(1), onFrame);
  return 0;
}
