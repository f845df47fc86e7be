#include "wirc/login_machine.h"

#include <algorithm>

namespace wircam::wirc {

using std::chrono::milliseconds;
using namespace login;

LoginMachine::LoginMachine(SessionConfig config, uint16_t statusPort, Clock::time_point now)
    : config_(std::move(config)), statusPort_(statusPort), attemptDeadline_(now) {}

std::optional<LoginMachine::Clock::time_point> LoginMachine::nextDeadline() const {
  switch (phase_) {
    case Phase::Waiting:
    case Phase::Connecting:
    case Phase::LoggingIn:
      return attemptDeadline_;
    case Phase::Discovering:
      return std::min(*attemptDeadline_, *discoveryEnds_);
    case Phase::LoggedIn:
      if (config_.linkTimeout.count() <= 0) return std::nullopt;
      return lastHeard_ + config_.linkTimeout;
    case Phase::Closed:
      return std::nullopt;
  }
  return std::nullopt;
}

std::string LoginMachine::deviceText() const {
  return device_ ? device_->toString() : config_.host;
}

LoginActions LoginMachine::onDeadline(Clock::time_point now) {
  auto deadline = nextDeadline();
  if (!deadline || now < *deadline) return {};
  switch (phase_) {
    case Phase::Waiting:
      return beginAttempt(now);
    case Phase::Discovering:
      return finishDiscovery(now);
    case Phase::Connecting:
      return fail("cannot connect to " + deviceText() +
                      " within the login timeout (is the device on and is that its address?)",
                  now);
    case Phase::LoggingIn:
      return fail("no WST from " + deviceText() +
                      " within the login timeout (the device accepted the connection but did "
                      "not answer the login)",
                  now);
    case Phase::LoggedIn: {
      auto silent = std::chrono::duration_cast<milliseconds>(now - lastHeard_);
      return fail("no status report from the device for " + std::to_string(silent.count()) +
                      " ms (link-timeout): it is off, out of range or gone",
                  now);
    }
    case Phase::Closed:
      return {};
  }
  return {};
}

LoginActions LoginMachine::beginAttempt(Clock::time_point now) {
  attemptDeadline_ = now + config_.loginTimeout;
  if (!config_.host.empty()) {
    auto resolved = SocketAddress::resolve(config_.host, config_.port);
    if (!resolved) return fail(resolved.error(), now);
    return connect(*resolved, "");
  }
  auto destination = SocketAddress::resolve(config_.discoveryAddress, config_.port);
  if (!destination) return fail(destination.error(), now);
  found_.clear();
  phase_ = Phase::Discovering;
  discoveryEnds_ = now + std::min(config_.loginTimeout / 2, kDiscoveryWindow);
  return {Discover{*destination}};
}

LoginActions LoginMachine::onDiscoveryAnswer(DiscoveredDevice device, Clock::time_point now) {
  if (phase_ != Phase::Discovering) return {};
  bool known = false;
  for (const auto& seen : found_) known = known || seen.address == device.address;
  if (!known) found_.push_back(std::move(device));
  // The named device answered: no need to wait for the others.
  if (!config_.device.empty() && pickDevice(found_, config_.device)) return finishDiscovery(now);
  return {};
}

LoginActions LoginMachine::finishDiscovery(Clock::time_point now) {
  auto picked = pickDevice(found_, config_.device);
  if (!picked) return fail(picked.error(), now);
  LoginActions actions{Close{}};  // the discovery socket
  auto connecting = connect(picked->address, picked->advertisement.name);
  actions.insert(actions.end(), connecting.begin(), connecting.end());
  return actions;
}

LoginActions LoginMachine::connect(const SocketAddress& device, const std::string& name) {
  device_ = device;
  status_.vehicleAddress = device.toString();
  if (!name.empty()) status_.deviceName = name;
  phase_ = Phase::Connecting;
  reported_ = {};
  rejectedThisConnection_ = 0;
  return {Connect{device}};
}

LoginActions LoginMachine::onConnected(Clock::time_point) {
  if (phase_ != Phase::Connecting) return {};
  phase_ = Phase::LoggingIn;
  return {Send{Tl{.system = static_cast<uint8_t>(SystemType::PcClient),
                  .version = {1, 0},
                  .priority = config_.priority,
                  .name = config_.transmitterName,
                  .statusPort = statusPort_}},
          Send{Ccfg{config_.periods}}, Send{Fcfg{config_.failsafe}}};
}

LoginActions LoginMachine::onConnectionLost(const std::string& why, Clock::time_point now) {
  if (phase_ == Phase::Waiting || phase_ == Phase::Closed) return {};
  return fail(why, now);
}

LoginActions LoginMachine::loggedIn(const Wst& wst, Clock::time_point now) {
  phase_ = Phase::LoggedIn;
  lastHeard_ = now;
  liveSince_ = now;
  status_.state = link::LinkState::Live;
  status_.reason.clear();
  status_.connectionId = wst.connectionId;
  status_.cameraCount = wst.cameraCount;
  ++status_.logins;
  controlAddress_ = device_->withPort(wst.controlPort);
  LoginActions actions{
      AimCommands{*controlAddress_},
      Emit{link::StateChanged{link::LinkState::Live,
                              "logged in to " + device_->toString() + " as connection " +
                                  std::to_string(wst.connectionId) + " (" +
                                  std::to_string(wst.cameraCount) +
                                  (wst.cameraCount == 1 ? " camera)" : " cameras)")}}};
  for (auto [camera, port] : streamPorts_)
    if (hasCamera(camera)) actions.push_back(Send{Stst{camera, port}});
  return actions;
}

LoginActions LoginMachine::onMessage(const Message& message, Clock::time_point now) {
  if (!connected()) return {};
  if (auto* wst = std::get_if<Wst>(&message))
    return phase_ == Phase::LoggingIn ? loggedIn(*wst, now) : LoginActions{};
  if (auto* agr = std::get_if<Agr>(&message)) return controlRight(*agr);
  if (auto* err = std::get_if<Err>(&message)) return deviceError(*err, now);
  if (auto* tlst = std::get_if<Tlst>(&message)) {
    if (listComplete_) transmitters_.clear();
    listComplete_ = false;
    transmitters_.push_back({tlst->connectionId, tlst->priority, tlst->name});
  } else if (std::holds_alternative<Tlend>(message)) {
    listComplete_ = true;
  }
  return {};
}

LoginActions LoginMachine::controlRight(const Agr& agr) {
  LoginActions actions;
  bool had = status_.hasControl;
  bool answersRequest =
      !controlRequests_.empty() && (agr.notification == AccessNotification::Denied ||
                                    agr.connectionId == controlRequests_.front());
  if (answersRequest) controlRequests_.pop_front();
  switch (agr.notification) {
    case AccessNotification::Granted:
      status_.hasControl = true;
      break;
    case AccessNotification::Revoked:
      status_.hasControl = false;
      break;
    case AccessNotification::Denied:
      break;
    case AccessNotification::Notification:
      status_.hasControl = agr.connectionId == status_.connectionId;
      break;
  }
  // The right's change first: whoever reports the answer reads the right
  // as it now is.
  if (had != status_.hasControl || agr.notification == AccessNotification::Notification)
    actions.push_back(Emit{link::ControlRightChanged{status_.hasControl, agr.name}});
  if (answersRequest) {
    bool denied = agr.notification == AccessNotification::Denied;
    actions.push_back(Emit{link::ControlRequestAnswered{
        !denied, denied ? "'" + agr.name +
                              "' holds it and only a transmitter of the highest priority may "
                              "hand it over"
                        : ""}});
  }
  if (!had && status_.hasControl) actions.push_back(StartCommands{});
  return actions;
}

LoginActions LoginMachine::deviceError(const Err& err, Clock::time_point now) {
  LoginActions actions;
  ++status_.errorsReceived;
  errors_.push_back(err);
  if (errors_.size() > 16) errors_.erase(errors_.begin());
  if (err.command == static_cast<uint8_t>(Command::Areq) && !controlRequests_.empty()) {
    controlRequests_.pop_front();
    actions.push_back(Emit{link::ControlRequestAnswered{false, errorCodeMeaning(err.code)}});
  }
  actions.push_back(
      Emit{link::DeviceRefused{commandName(err.command), err.code, errorCodeMeaning(err.code)}});
  // The login itself refused (unauthorised, busy): no WST will come.
  if (phase_ == Phase::LoggingIn && err.command == static_cast<uint8_t>(Command::Tl)) {
    auto failed = fail(std::string("the device refused the login: ") + errorCodeMeaning(err.code) +
                           " (ERR " + std::to_string(err.code) + ")",
                       now);
    actions.insert(actions.end(), failed.begin(), failed.end());
  }
  return actions;
}

LoginActions LoginMachine::onParserStats(const StreamParserStats& stats, Clock::time_point now) {
  if (!connected()) return {};
  // Garbage is counted in bytes: 64 of them weigh as one bad message.
  uint64_t rejected =
      stats.badCrc + stats.unknownCommands + stats.invalidMessages + stats.garbageBytes / 64;
  if (rejected == rejectedThisConnection_) return {};
  rejectedUnreported_ += rejected - rejectedThisConnection_;
  status_.inputRejected += rejected - rejectedThisConnection_;
  rejectedThisConnection_ = rejected;
  LoginActions actions;
  if (now - lastSummary_ >= kRejectSummaryPeriod) {
    auto since = [](uint64_t current, uint64_t before) { return std::to_string(current - before); };
    actions.push_back(Emit{link::InputRejected{
        rejectedUnreported_,
        since(stats.badCrc, reported_.badCrc) + " bad CRC, " +
            since(stats.unknownCommands, reported_.unknownCommands) + " unknown commands, " +
            since(stats.invalidMessages, reported_.invalidMessages) + " invalid, " +
            since(stats.garbageBytes, reported_.garbageBytes) + " bytes of garbage"}});
    reported_ = stats;
    rejectedUnreported_ = 0;
    lastSummary_ = now;
  }
  if (rejectedThisConnection_ > config_.maxBadMessages) {
    auto failed = fail("the device sent " + std::to_string(rejectedThisConnection_) +
                           " malformed messages: dropped as misbehaving",
                       now);
    actions.insert(actions.end(), failed.begin(), failed.end());
  }
  return actions;
}

LoginActions LoginMachine::onStatusReport(const SocketAddress& from, const Psd& psd,
                                          Clock::time_point now) {
  if (!device_ || !device_->sameHost(from)) return {};  // not our device
  link::Telemetry telemetry{
      .batteryVolts = psd.batteryMillivolts / 1000.0,
      .analogVolts = psd.analogMillivolts / 1000.0,
      .inputs = static_cast<uint32_t>(psd.inputs[0] | psd.inputs[1] << 1 | psd.inputs[2] << 2 |
                                      psd.inputs[3] << 3),
      .received = now};
  lastHeard_ = now;
  status_.lastStatus = psd;
  status_.telemetry = telemetry;
  return {Emit{link::TelemetryReceived{telemetry}}};
}

LoginActions LoginMachine::relogin(const std::string& why, Clock::time_point now) {
  if (!connected()) return {};
  return fail(why, now, Retry::AtOnceForNewSettings);
}

LoginActions LoginMachine::fail(const std::string& why, Clock::time_point now, Retry retryWhen) {
  bool retryAtOnce = retryWhen == Retry::AtOnceForNewSettings;
  if (liveSince_ && now - *liveSince_ >= kHealthyLink) backoff_ = kFirstBackoff;
  liveSince_.reset();
  ++failedAttempts_;
  LoginActions actions{Close{}};
  bool retry = config_.reconnect || retryAtOnce;
  link::LinkState state = !retry                               ? link::LinkState::Failed
                          : status_.logins == 0 || retryAtOnce ? link::LinkState::Connecting
                                                               : link::LinkState::Lost;
  milliseconds wait = retryAtOnce ? milliseconds(0) : backoff_;
  std::string reason = why;
  if (retry && !retryAtOnce) reason += "; retrying in " + std::to_string(wait.count()) + " ms";
  actions.push_back(Emit{link::StateChanged{state, reason}});
  if (status_.hasControl) actions.push_back(Emit{link::ControlRightChanged{false, ""}});
  status_.hasControl = false;
  status_.state = state;
  status_.reason = why;
  controlAddress_.reset();
  controlRequests_.clear();
  if (!retry) {
    phase_ = Phase::Closed;
    return actions;
  }
  phase_ = Phase::Waiting;
  if (!retryAtOnce) backoff_ = std::min(backoff_ * 2, kMaxBackoff);
  attemptDeadline_ = now + wait;
  return actions;
}

LoginActions LoginMachine::close() {
  LoginActions actions;
  if (connected())
    for (const auto& [camera, port] : streamPorts_) {
      if (!hasCamera(camera)) continue;
      auto stop = send(Est{camera});
      actions.insert(actions.end(), stop.begin(), stop.end());
    }
  actions.emplace_back(Close{});
  phase_ = Phase::Closed;
  return actions;
}

LoginActions LoginMachine::startStream(uint8_t camera, uint16_t port) {
  streamPorts_[camera] = port;
  // Not live yet: the login sends it.
  if (phase_ != Phase::LoggedIn || !hasCamera(camera)) return {};
  return {Send{Stst{camera, port}}};
}

LoginActions LoginMachine::stopStream(uint8_t camera) {
  streamPorts_.erase(camera);
  if (phase_ == Phase::LoggedIn && !hasCamera(camera)) return {};
  return send(Est{camera});
}

bool LoginMachine::hasCamera(uint8_t camera) const {
  // Never asked for otherwise: the device's refusal (an ERR names the
  // command, not the camera) would reach every camera of the link. The
  // source says "no camera N" from the same count.
  return camera < status_.cameraCount;
}

LoginActions LoginMachine::requestControl(uint8_t connectionId) {
  if (!connected()) return {Emit{link::ControlRequestAnswered{false, "not logged in"}}};
  controlRequests_.push_back(connectionId);
  return {Send{Areq{connectionId}}};
}

LoginActions LoginMachine::listTransmitters() {
  listComplete_ = false;
  transmitters_.clear();
  return send(Tlr{});
}

LoginActions LoginMachine::send(const Message& message) {
  if (!connected()) return {};
  return {Send{message}};
}

}  // namespace wircam::wirc
