#include "rcoip/reply_monitor.h"

namespace wircam::rcoip {

ReplyMonitor::ReplyMonitor(SocketAddress receiver, std::chrono::milliseconds failInterval)
    : receiver_(receiver), failInterval_(failInterval) {
  status_.vehicleAddress = receiver_.toString();
  status_.hasControl = true;  // RCOIP has no control right: the transmitter always steers
  status_.reason = "waiting for the receiver's first reply";
}

std::vector<link::LinkEvent> ReplyMonitor::onDatagram(const SocketAddress& from,
                                                      std::span<const uint8_t> datagram,
                                                      Clock::time_point now) {
  if (!(from == receiver_)) {
    ++status_.foreignDatagrams;
    return {};
  }
  auto reply = decodeReply(datagram);
  if (!reply) {
    rejected_.count(decodeErrorName(reply.error()));
    status_.inputRejected = rejected_.total();
    return {};
  }
  link::Telemetry telemetry{.batteryVolts = reply->batteryVolts(), .received = now};
  if (reply->rssi) telemetry.rssi = *reply->rssi;
  lastReply_ = now;
  ++status_.replies;
  status_.lastReply = *reply;
  status_.telemetry = telemetry;
  std::vector<link::LinkEvent> events;
  if (status_.state != link::LinkState::Live) {
    bool again = status_.state == link::LinkState::Lost;
    status_.state = link::LinkState::Live;
    status_.reason.clear();
    ++status_.logins;
    events.push_back(link::StateChanged{
        link::LinkState::Live,
        (again ? "replies again from " : "replies from ") + receiver_.toString()});
  }
  events.push_back(link::TelemetryReceived{telemetry});
  return events;
}

std::optional<ReplyMonitor::Clock::time_point> ReplyMonitor::nextDeadline() const {
  if (status_.state != link::LinkState::Live) return std::nullopt;
  return lastReply_ + failInterval_;
}

std::vector<link::LinkEvent> ReplyMonitor::onDeadline(Clock::time_point now) {
  auto deadline = nextDeadline();
  if (!deadline || now < *deadline) return {};
  auto silent = std::chrono::duration_cast<std::chrono::milliseconds>(now - lastReply_);
  std::string reason = "no reply from " + receiver_.toString() + " for " +
                       std::to_string(silent.count()) +
                       " ms (fail interval): it is off, out of range or gone";
  status_.state = link::LinkState::Lost;
  status_.reason = reason;
  return {link::StateChanged{link::LinkState::Lost, reason}};
}

std::optional<link::LinkEvent> ReplyMonitor::rejectSummary(Clock::time_point now) {
  if (auto summary = rejected_.summary(now)) return link::LinkEvent{*summary};
  return std::nullopt;
}

}  // namespace wircam::rcoip
