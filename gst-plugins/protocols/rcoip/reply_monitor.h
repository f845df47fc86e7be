// What the RCOIP receiver's replies say about the link, without I/O: a
// reply makes the link live and brings RSSI and battery; `failInterval`
// without one makes it lost; datagrams from anyone else are counted and
// ignored, malformed replies tallied and summed up once a second. The
// transmitter feeds it datagrams and deadlines with their time; unit tests
// do the same with a fake clock.
#pragma once

#include <chrono>
#include <optional>
#include <span>
#include <vector>

#include "common/socket.h"
#include "link/event_loop.h"
#include "link/reject_tally.h"
#include "link/vehicle_link.h"
#include "rcoip/rcoip_messages.h"

namespace wircam::rcoip {

struct TransmitterStatus : link::LinkStatus {
  std::optional<Reply> lastReply;
  uint64_t replies = 0;
  uint64_t foreignDatagrams = 0;  // from anyone but the receiver: ignored
};

class ReplyMonitor {
 public:
  using Clock = link::Clock;

  ReplyMonitor(SocketAddress receiver, std::chrono::milliseconds failInterval);

  // One datagram from `from`, received at `now`: the events it causes.
  std::vector<link::LinkEvent> onDatagram(const SocketAddress& from,
                                          std::span<const uint8_t> datagram, Clock::time_point now);
  // nextDeadline() has come (or passed).
  std::vector<link::LinkEvent> onDeadline(Clock::time_point now);
  // The summary of malformed replies, at most once a second.
  std::optional<link::LinkEvent> rejectSummary(Clock::time_point now);
  // While live: when the link counts as lost without another reply.
  std::optional<Clock::time_point> nextDeadline() const;

  const TransmitterStatus& status() const { return status_; }
  void countCommandSent() { ++status_.commandsSent; }

 private:
  const SocketAddress receiver_;
  const std::chrono::milliseconds failInterval_;
  TransmitterStatus status_;
  Clock::time_point lastReply_{};
  link::RejectTally rejected_;
};

}  // namespace wircam::rcoip
