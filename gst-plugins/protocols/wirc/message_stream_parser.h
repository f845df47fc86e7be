// Cuts the TCP byte stream of the control connection into messages. Input may
// arrive in any pieces; garbage is skipped, a bad CRC resyncs on the next
// AA BB, and an unknown command with a valid CRC is reported and skipped.
// Memory is bounded: at most one partial frame (261 bytes) is kept.
#pragma once

#include <array>
#include <cstdint>
#include <functional>
#include <span>

#include "wirc/messages.h"

namespace wircam::wirc {

struct StreamParserStats {
  uint64_t messages = 0;      // decoded and valid
  uint64_t garbageBytes = 0;  // skipped while looking for AA BB
  uint64_t badCrc = 0;
  uint64_t unknownCommands = 0;
  uint64_t invalidMessages = 0;  // wrong length or a field rule broken
};

class MessageStreamParser {
 public:
  // Called once per frame found: a message, or the error that frame had.
  using Handler = std::function<void(const Expected<Message, ProtocolError>&)>;

  void feed(std::span<const uint8_t> bytes, const Handler& handler);

  // Bytes of an unfinished frame held back for the next feed().
  size_t pendingBytes() const { return size_; }
  const StreamParserStats& stats() const { return stats_; }

 private:
  // Drops the frame start at buffer_[0] and moves to the next 0xAA in what
  // was buffered, so a false sync inside garbage cannot hide a real frame.
  void resync();
  // Removes a frame of frameBytes from the front, then any garbage up to the
  // next 0xAA already buffered.
  void consume(size_t frameBytes);
  size_t frameSizeNeeded() const;

  std::array<uint8_t, kMaxFrameSize> buffer_{};
  size_t size_ = 0;
  StreamParserStats stats_;
};

}  // namespace wircam::wirc
