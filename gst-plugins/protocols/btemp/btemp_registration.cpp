#include "btemp/btemp_registration.h"

namespace wircam::btemp {

using std::chrono::milliseconds;
using namespace registration;

Registration::Registration(NodeInfo self, std::string host, uint16_t port,
                           milliseconds keepaliveTimeout, Clock::time_point now)
    : self_(self),
      host_(std::move(host)),
      port_(port),
      keepaliveTimeout_(keepaliveTimeout),
      deadline_(now) {
  status_.reason = "looking for the robot";
  if (!host_.empty())
    if (auto named = SocketAddress::resolve(host_, port_)) namedHost_ = *named;
}

Registration::Clock::time_point Registration::nextDeadline() const {
  return phase_ == Phase::Registered ? lastHeard_ + keepaliveTimeout_ : deadline_;
}

RegistrationActions Registration::onDeadline(Clock::time_point now) {
  if (now < nextDeadline()) return {};
  switch (phase_) {
    case Phase::Probing:
      deadline_ = now + kProbePeriod;
      // After a loss the robot is looked for where it was.
      if (robot_) return {Probe{robot_->host(), robot_->port()}};
      return {Probe{host_, port_}};
    case Phase::Registering:
      deadline_ = now + kProbePeriod;
      return {Send{Rctr{.node = self_.node}, *robot_}};
    case Phase::Registered:
      break;
  }
  auto silent = std::chrono::duration_cast<milliseconds>(now - lastHeard_);
  std::string reason = "nothing from the robot at " + robot_->toString() + " for " +
                       std::to_string(silent.count()) +
                       " ms (keepalive timeout): looking for it again";
  phase_ = Phase::Probing;
  deadline_ = now;  // at once
  status_.state = link::LinkState::Lost;
  status_.reason = reason;
  status_.hasControl = false;
  return {Emit{link::StateChanged{link::LinkState::Lost, reason}},
          Emit{link::ControlRightChanged{false, ""}}};
}

RegistrationActions Registration::onDatagram(const SocketAddress& from,
                                             std::span<const uint8_t> datagram,
                                             Clock::time_point now) {
  bool foreign = robot_ ? !(from == *robot_) : namedHost_ && !from.sameHost(*namedHost_);
  if (foreign) {
    ++status_.foreignDatagrams;
    return {};
  }
  auto message = decode(datagram);
  if (!message) {
    rejected_.count(decodeErrorName(message.error()));
    status_.inputRejected = rejected_.total();
    return {};
  }
  return handle(*message, from, now);
}

RegistrationActions Registration::handle(const Message& message, const SocketAddress& from,
                                         Clock::time_point now) {
  if (robot_ && from == *robot_) lastHeard_ = now;
  if (const auto* piak = std::get_if<Piak>(&message)) {
    if (phase_ != Phase::Probing || nodeTypeOf(piak->node.flags) != NodeType::Robot) return {};
    robot_ = from;
    status_.robot = piak->node;
    status_.vehicleAddress = from.toString();
    phase_ = Phase::Registering;
    lastHeard_ = now;
    deadline_ = now;  // RCTR at once
    return {};
  }
  if (std::holds_alternative<Rcak>(message)) {
    if (phase_ != Phase::Registering) return {};
    bool again = status_.logins > 0;
    phase_ = Phase::Registered;
    status_.state = link::LinkState::Live;
    status_.reason.clear();
    status_.hasControl = true;
    ++status_.logins;
    std::string robot = status_.vehicleAddress + " (" + formatGuid(status_.robot->node) + ")";
    return {Emit{link::StateChanged{
                link::LinkState::Live,
                (again ? "registered again with robot " : "registered with robot ") + robot}},
            Emit{link::ControlRightChanged{true, ""}}, StartCommands{}};
  }
  if (const auto* pins = std::get_if<Pins>(&message)) {
    link::Telemetry telemetry{.inputs = pins->inputs, .outputs = pins->outputs, .received = now};
    size_t next = 0;
    for (int pin = 0; pin < 32; ++pin)
      if (pins->pdmMask >> pin & 1) telemetry.pdmDuty[pin] = pins->duty[next++];
    status_.lastPins = *pins;
    status_.telemetry = telemetry;
    return {Emit{link::TelemetryReceived{telemetry}}};
  }
  if (const auto* ping = std::get_if<Ping>(&message)) {
    if (!ping->sender || wantsResponse(ping->sender->flags)) return {Send{Piak{self_}, from}};
    return {};
  }
  if (std::holds_alternative<VideoSegment>(message)) ++status_.videoSegments;
  // IDLE only shows the robot is alive (lastHeard_); RCTR and CTRL are a
  // controller's, not a robot's, to send: ignored.
  return {};
}

std::optional<link::LinkEvent> Registration::rejectSummary(Clock::time_point now) {
  if (auto summary = rejected_.summary(now)) return link::LinkEvent{*summary};
  return std::nullopt;
}

}  // namespace wircam::btemp
