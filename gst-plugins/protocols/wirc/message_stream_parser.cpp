#include "wirc/message_stream_parser.h"

#include <algorithm>
#include <cstring>

#include "wirc/crc16.h"

namespace wircam::wirc {

size_t MessageStreamParser::frameSizeNeeded() const {
  return size_ < kHeaderSize ? kHeaderSize : kHeaderSize + buffer_[3] + kCrcSize;
}

void MessageStreamParser::consume(size_t frameBytes) {
  auto* next = std::find(buffer_.begin() + frameBytes, buffer_.begin() + size_, kSync1);
  size_t dropped = static_cast<size_t>(next - buffer_.begin());
  stats_.garbageBytes += dropped - frameBytes;
  std::memmove(buffer_.data(), buffer_.data() + dropped, size_ - dropped);
  size_ -= dropped;
}

void MessageStreamParser::resync() {
  ++stats_.garbageBytes;  // the false 0xAA itself
  consume(1);
}

void MessageStreamParser::feed(std::span<const uint8_t> bytes, const Handler& handler) {
  for (;;) {
    if (size_ == 0) {
      auto start = std::find(bytes.begin(), bytes.end(), kSync1);
      stats_.garbageBytes += static_cast<uint64_t>(start - bytes.begin());
      bytes = bytes.subspan(static_cast<size_t>(start - bytes.begin()));
      if (bytes.empty()) return;
    }

    // After a resync the buffer may already hold more than the next frame.
    size_t needed = frameSizeNeeded();
    size_t take = size_ < needed ? std::min(needed - size_, bytes.size()) : 0;
    std::memcpy(buffer_.data() + size_, bytes.data(), take);
    size_ += take;
    bytes = bytes.subspan(take);

    if (size_ >= 2 && buffer_[1] != kSync2) {
      resync();
      continue;
    }
    size_t frameSize = frameSizeNeeded();
    if (size_ < frameSize) {
      if (bytes.empty()) return;
      continue;
    }

    std::span<const uint8_t> frame(buffer_.data(), frameSize);
    uint8_t command = frame[2];
    uint16_t crc = static_cast<uint16_t>(frame[frameSize - 2] << 8 | frame[frameSize - 1]);
    if (crc != crc16Xmodem(frame.subspan(2, frameSize - 2 - kCrcSize))) {
      ++stats_.badCrc;
      handler(unexpected(ProtocolError{ErrorKind::BadCrc, command, "CRC", "checksum mismatch"}));
      resync();
      continue;
    }

    auto message =
        decodeBody(command, frame.subspan(kHeaderSize, frameSize - kHeaderSize - kCrcSize));
    if (message)
      ++stats_.messages;
    else if (message.error().kind == ErrorKind::UnknownCommand)
      ++stats_.unknownCommands;
    else
      ++stats_.invalidMessages;
    consume(frameSize);
    handler(message);
  }
}

}  // namespace wircam::wirc
