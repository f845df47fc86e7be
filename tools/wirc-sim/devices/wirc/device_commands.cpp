// What each message of a transmitter does to the device: the login (TL,
// CCFG, FCFG, then WST), configuration, the control right, streams,
// EXTOUT.
#include "devices/wirc/device_impl.h"

namespace wircam::wirc {

namespace {

template <class... Ts>
struct Overloaded : Ts... {
  using Ts::operator()...;
};
template <class... Ts>
Overloaded(Ts...) -> Overloaded<Ts...>;

}  // namespace

using device_detail::Connection;

void Device::Impl::handleMessage(Connection& c, const Expected<Message, ProtocolError>& result) {
  if (!result) {
    const auto& error = result.error();
    log("connection " + std::to_string(c.id) + ": " + error.message());
    // A bad CRC leaves the command byte itself in doubt: nothing to answer.
    if (error.kind != ErrorKind::BadCrc) sendError(c, error.command, ErrorCode::Format);
    return;
  }
  std::visit(Overloaded{[&](const Tl& m) { handle(c, m); }, [&](const Ccfg& m) { handle(c, m); },
                        [&](const Fcfg& m) { handle(c, m); }, [&](const Dcfg& m) { handle(c, m); },
                        [&](const Wcfg& m) { handle(c, m); }, [&](const Tlr& m) { handle(c, m); },
                        [&](const Areq& m) { handle(c, m); }, [&](const Fwup& m) { handle(c, m); },
                        [&](const Stst& m) { handle(c, m); }, [&](const Est& m) { handle(c, m); },
                        [&](const Extout& m) { handle(c, m); },
                        [&](const auto& m) {
                          // PCD belongs on UDP; the rest flow device → transmitter.
                          log("connection " + std::to_string(c.id) + ": unexpected " +
                              commandName(static_cast<uint8_t>(m.kCommand)));
                          sendError(c, static_cast<uint8_t>(m.kCommand), ErrorCode::Format);
                        }},
             *result);
}

bool Device::Impl::requireLogin(Connection& c, Command command) {
  if (c.login) return true;
  sendError(c, static_cast<uint8_t>(command), ErrorCode::Unauthorised);
  return false;
}

bool Device::Impl::requireStarted(Connection& c, Command command) {
  if (c.started) return true;
  sendError(c, static_cast<uint8_t>(command), ErrorCode::Unauthorised);
  return false;
}

bool Device::Impl::isFirst(const Connection& c) const {
  for (const auto& other : connections_)
    if (other.login && !other.closing && other.order < c.order) return false;
  return true;
}

bool Device::Impl::requireFirst(Connection& c, Command command) {
  if (!requireLogin(c, command)) return false;
  if (isFirst(c)) return true;
  sendError(c, static_cast<uint8_t>(command), ErrorCode::Denied);
  return false;
}

void Device::Impl::handle(Connection& c, const Tl& m) {
  if (c.login) return sendError(c, static_cast<uint8_t>(Command::Tl), ErrorCode::Format);
  c.login = m;
  log("connection " + std::to_string(c.id) + ": login '" + m.name + "' priority " +
      std::to_string(m.priority) + ", status port " + std::to_string(m.statusPort));
}

void Device::Impl::handle(Connection& c, const Ccfg& m) {
  if (!requireLogin(c, Command::Ccfg)) return;
  c.ccfgSeen = true;  // a refused CCFG still counts for the login sequence
  if (requireFirst(c, Command::Ccfg)) periods_ = m.periods;
  maybeStart(c);
}

void Device::Impl::handle(Connection& c, const Fcfg& m) {
  if (!requireLogin(c, Command::Fcfg)) return;
  c.fcfgSeen = true;
  if (requireFirst(c, Command::Fcfg)) failsafe_ = m.values;
  maybeStart(c);
}

void Device::Impl::handle(Connection& c, const Dcfg& m) {
  if (!requireFirst(c, Command::Dcfg)) return;
  pendingName_ = m.name;
  log("name will be '" + m.name + "' after the next restart");
}

void Device::Impl::handle(Connection& c, const Wcfg& m) {
  if (!requireFirst(c, Command::Wcfg)) return;
  // The password is never logged.
  log("WiFi set to SSID '" + m.ssid + "', " + (m.accessPoint ? "access point" : "station") + ", " +
      (m.secured ? "WPA" : "open") + ", channel " + std::to_string(m.channel) + ", country '" +
      m.country + "' (after the next restart)");
}

void Device::Impl::handle(Connection& c, const Tlr&) {
  if (!requireStarted(c, Command::Tlr)) return;
  for (auto& other : connections_) {
    if (!other.started || other.closing) continue;
    sendMessage(c, Tlst{other.id, other.login->priority, other.login->name});
  }
  sendMessage(c, Tlend{});
}

void Device::Impl::handle(Connection& c, const Areq& m) {
  if (!requireStarted(c, Command::Areq)) return;
  // Only a transmitter of the highest priority present may hand out the
  // control right (ties allowed), and only to a logged-in transmitter.
  uint8_t highest = 0;
  for (const auto& other : connections_)
    if (other.started && !other.closing) highest = std::max(highest, other.login->priority);
  Connection* target = findConnection(m.connectionId);
  Connection* current = controller();
  if (c.login->priority < highest || !target || !target->started) {
    Agr denied{};
    if (current) denied = Agr{current->id, current->login->priority, current->login->name, {}};
    denied.notification = AccessNotification::Denied;
    log("connection " + std::to_string(c.id) + ": AREQ for " + std::to_string(m.connectionId) +
        " denied");
    return sendMessage(c, denied);
  }
  if (target == current) {
    return sendMessage(c, Agr{target->id, target->login->priority, target->login->name,
                              c.id == target->id ? AccessNotification::Granted
                                                 : AccessNotification::Notification});
  }
  giveControl(*target);
}

void Device::Impl::handle(Connection& c, const Fwup& m) {
  if (!requireStarted(c, Command::Fwup)) return;
  char md5[33] = {};
  for (size_t i = 0; i < m.md5.size(); ++i) std::snprintf(md5 + 2 * i, 3, "%02x", m.md5[i]);
  log(std::string("firmware update ") + md5 + ": disconnecting everyone and restarting");
  restart();
}

void Device::Impl::handle(Connection& c, const Stst& m) {
  if (!requireStarted(c, Command::Stst)) return;
  if (m.camera >= config_.cameras || m.port == 0) {
    log("connection " + std::to_string(c.id) + ": STST camera " + std::to_string(m.camera) +
        " port " + std::to_string(m.port) + " refused");
    return sendError(c, static_cast<uint8_t>(Command::Stst), ErrorCode::Format);
  }
  StreamKey key{c.id, m.camera};
  streams_.erase(key);
  Impairments impairments = config_.impairments;
  impairments.seed += c.id * 31u + m.camera;  // distinct, repeatable per stream
  auto destination =
      c.peer.withPort(impairments.misdirectPort ? impairments.misdirectPort : m.port);
  streams_.emplace(key, StreamSender(video_.get(), stray_.get(), destination, config_.fragmentSize,
                                     impairments));
  log("camera " + std::to_string(m.camera) + " streaming to " + destination.toString());
}

void Device::Impl::handle(Connection& c, const Est& m) {
  if (!requireStarted(c, Command::Est)) return;
  auto stream = streams_.find({c.id, m.camera});
  if (stream == streams_.end()) {
    log("connection " + std::to_string(c.id) + ": EST for camera " + std::to_string(m.camera) +
        ", which was not streaming");
    return;
  }
  stream->second.flush();
  streams_.erase(stream);
  log("camera " + std::to_string(m.camera) + " stopped for connection " + std::to_string(c.id));
}

void Device::Impl::handle(Connection& c, const Extout& m) {
  if (!requireStarted(c, Command::Extout)) return;
  log("EXTOUT to port " + std::to_string(m.destination) + ": " + std::to_string(m.data.size()) +
      " bytes");
}

void Device::Impl::maybeStart(Connection& c) {
  if (c.started || !c.ccfgSeen || !c.fcfgSeen || c.closing) return;
  c.started = true;
  ++localStats_.logins;
  sendMessage(c, Wst{c.id, static_cast<uint8_t>(config_.cameras), controlPort_});
  log("connection " + std::to_string(c.id) + " logged in");
  if (!controller_) giveControl(c);
}

void Device::Impl::giveControl(Connection& to) {
  Connection* previous = controller();
  controller_ = to.id;
  controlDeadline_ = DeviceClock::now() + config_.pcdTimeout;
  lastPcd_.reset();
  Agr agr{to.id, to.login->priority, to.login->name, AccessNotification::Granted};
  for (auto& c : connections_) {
    if (!c.started || c.closing) continue;
    agr.notification = &c == &to        ? AccessNotification::Granted
                       : &c == previous ? AccessNotification::Revoked
                                        : AccessNotification::Notification;
    sendMessage(c, agr);
  }
  log("control right to connection " + std::to_string(to.id) + " ('" + to.login->name + "')");
}

Connection* Device::Impl::findConnection(uint8_t id) {
  for (auto& c : connections_)
    if (c.id == id && !c.closing) return &c;
  return nullptr;
}

}  // namespace wircam::wirc
