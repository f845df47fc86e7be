// The receive side of one camera stream: which datagrams belong to it and
// what they assemble into. Only the device may feed the stream, and only
// from the port that first sent it a valid packet in the current login; a
// junk flood cannot claim the stream, and a port that stops sending valid
// packets gives way to the next valid sender from the device. A new login
// (the device streams from a new port) starts the stream over. Time comes
// from the caller, so the policy is tested without sleeping.
#pragma once

#include <chrono>
#include <optional>
#include <span>

#include "common/socket.h"
#include "wirc/frame_assembler.h"

namespace wircam::wirc {

struct StreamReceiverStats {
  AssemblerStats assembler;
  uint64_t packetsForeign = 0;  // from another host, or another port than the pinned one
};

class StreamReceiver {
 public:
  using Clock = std::chrono::steady_clock;

  // How long a pinned sender may go without a valid packet before another
  // port of the device may take over.
  static constexpr std::chrono::milliseconds kRepinAfter{1000};

  explicit StreamReceiver(FrameAssemblerConfig config = {}) : assembler_(config) {}

  // The device to accept packets from, and its login count: a new login
  // forgets the pinned port and the frames in flight.
  void follow(const SocketAddress& device, uint64_t login);

  void push(const SocketAddress& from, std::span<const uint8_t> datagram, Clock::time_point now,
            const FrameAssembler::FrameHandler& onFrame);
  void expire(Clock::time_point now, const FrameAssembler::FrameHandler& onFrame) {
    assembler_.expire(now, onFrame);
  }
  std::optional<Clock::time_point> nextDeadline() const { return assembler_.nextDeadline(); }
  void recycle(FrameBuffer&& buffer) { assembler_.recycle(std::move(buffer)); }

  StreamReceiverStats stats() const { return {assembler_.stats(), foreign_}; }
  std::optional<uint16_t> pinnedPort() const { return pinnedPort_; }

 private:
  FrameAssembler assembler_;
  std::optional<SocketAddress> device_;
  uint64_t login_ = 0;
  std::optional<uint16_t> pinnedPort_;
  Clock::time_point lastValid_{};
  uint64_t foreign_ = 0;
};

}  // namespace wircam::wirc
