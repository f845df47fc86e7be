#include "wirc/stream_receiver.h"

namespace wircam::wirc {

void StreamReceiver::follow(const SocketAddress& device, uint64_t login) {
  if (device_ && *device_ == device && login == login_) return;
  device_ = device;
  login_ = login;
  pinnedPort_.reset();
  assembler_.reset();
}

void StreamReceiver::push(const SocketAddress& from, std::span<const uint8_t> datagram,
                          Clock::time_point now, const FrameAssembler::FrameHandler& onFrame) {
  if (!device_ || !from.sameHost(*device_)) {
    ++foreign_;
    return;
  }
  bool pinnedElsewhere = pinnedPort_ && *pinnedPort_ != from.port();
  if (pinnedElsewhere && now - lastValid_ < kRepinAfter) {
    ++foreign_;
    return;
  }
  auto packet = parseMjpegPacket(datagram);
  if (!packet) {
    // Counted by the assembler (keepalive or invalid); pins nothing.
    if (pinnedElsewhere)
      ++foreign_;
    else
      assembler_.pushDatagram(datagram, now, onFrame);
    return;
  }
  if (pinnedElsewhere) assembler_.reset();  // the old sender went quiet: follow the new one
  pinnedPort_ = from.port();
  lastValid_ = now;
  assembler_.pushPacket(*packet, now, onFrame);
}

}  // namespace wircam::wirc
