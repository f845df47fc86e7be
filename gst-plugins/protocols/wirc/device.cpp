#include "wirc/device.h"

#include <poll.h>
#include <sys/eventfd.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <cerrno>
#include <deque>
#include <list>
#include <map>
#include <mutex>
#include <thread>

#include "wirc/message_stream_parser.h"
#include "wirc/mjpeg_packet.h"

namespace wircam::wirc {

namespace {

using std::chrono::duration_cast;
using std::chrono::milliseconds;

// One TCP connection of a transmitter, from accept to close.
struct Connection {
  UniqueFd fd;
  SocketAddress peer;
  uint8_t id = 0;
  uint64_t order = 0;  // the lowest among the logged-in is the "first" transmitter
  MessageStreamParser parser;
  std::optional<Tl> login;
  bool ccfgSeen = false;
  bool fcfgSeen = false;
  bool started = false;  // WST sent
  bool closing = false;  // closed at the end of this loop turn
  std::string closeReason;
};

struct StreamKey {
  uint8_t connection;
  uint8_t camera;
  auto operator<=>(const StreamKey&) const = default;
};

template <class... Ts>
struct Overloaded : Ts... {
  using Ts::operator()...;
};
template <class... Ts>
Overloaded(Ts...) -> Overloaded<Ts...>;

}  // namespace

class Device::Impl {
 public:
  Impl(DeviceConfig config, std::shared_ptr<DeviceScene> scene, Logger logger)
      : config_(std::move(config)),
        scene_(std::move(scene)),
        logger_(std::move(logger)),
        name_(config_.name),
        batteryMillivolts_(config_.batteryMillivolts) {
    periods_.fill(20000);
    failsafe_ = neutralChannels();
  }

  std::optional<std::string> open();
  void run();
  void requestStop();

  uint16_t port_ = 0;
  uint16_t controlPort_ = 0;
  std::thread thread_;

  // Guards the copies that other threads read; the device thread alone
  // writes them, and holds the lock only to copy.
  mutable std::mutex mutex_;
  DeviceStats stats_;
  ChannelOutputs outputs_;
  std::string publishedName_;
  std::deque<DeviceClock::time_point> pcdArrivals_;

 private:
  void log(const std::string& text) {
    if (logger_) logger_(text);
  }
  std::optional<std::string> openListener();
  void runTimers(DeviceClock::time_point now);
  int pollTimeoutMs(DeviceClock::time_point now) const;
  void acceptConnection();
  void readConnection(Connection& connection);
  void readDiscovery();
  void readPcd(DeviceClock::time_point now);
  void handleMessage(Connection& connection, const Expected<Message, ProtocolError>& result);
  void handle(Connection& c, const Tl& m);
  void handle(Connection& c, const Ccfg& m);
  void handle(Connection& c, const Fcfg& m);
  void handle(Connection& c, const Dcfg& m);
  void handle(Connection& c, const Wcfg& m);
  void handle(Connection& c, const Tlr& m);
  void handle(Connection& c, const Areq& m);
  void handle(Connection& c, const Fwup& m);
  void handle(Connection& c, const Stst& m);
  void handle(Connection& c, const Est& m);
  void handle(Connection& c, const Extout& m);
  void sendMessage(Connection& connection, const Message& message);
  void sendError(Connection& connection, uint8_t command, ErrorCode code);
  bool requireLogin(Connection& connection, Command command);
  bool requireStarted(Connection& connection, Command command);
  bool requireFirst(Connection& connection, Command command);
  bool isFirst(const Connection& connection) const;
  void maybeStart(Connection& connection);
  void giveControl(Connection& to);
  Connection* findConnection(uint8_t id);
  Connection* controller() { return controller_ ? findConnection(*controller_) : nullptr; }
  void enterFailsafe(const std::string& why);
  void closeConnection(Connection& connection, std::string reason);
  void sweepClosed();
  void restart();
  void tickFrame(DeviceClock::time_point now);
  void sendStatus();
  void publish();
  uint8_t allocateId();

  DeviceConfig config_;
  std::shared_ptr<DeviceScene> scene_;
  Logger logger_;
  std::atomic<bool> stopping_{false};
  UniqueFd wake_;
  UniqueFd listener_;
  UniqueFd discovery_;
  UniqueFd control_;
  UniqueFd video_;
  UniqueFd stray_;
  std::list<Connection> connections_;
  std::map<StreamKey, StreamSender> streams_;
  ChannelValues periods_{};
  ChannelValues failsafe_{};
  ChannelOutputs localOutputs_;
  std::optional<uint8_t> controller_;
  DeviceClock::time_point controlDeadline_;  // PCD must come before this
  std::optional<DeviceClock::time_point> lastPcd_;
  DeviceClock::time_point nextPsd_;
  DeviceClock::time_point nextFrame_;
  std::optional<DeviceClock::time_point> lastTick_;
  std::optional<DeviceClock::time_point> restartDone_;
  std::string name_;
  std::string pendingName_;
  double batteryMillivolts_;
  uint8_t nextId_ = 1;
  uint64_t nextOrder_ = 0;
  DeviceStats localStats_;
  std::array<uint8_t, kMaxDatagramSize> buffer_{};
};

std::optional<std::string> Device::Impl::openListener() {
  auto address = SocketAddress::resolve(config_.bindAddress, port_);
  if (!address) return address.error();
  auto listener = listenTcp(*address);
  if (!listener) return listener.error();
  setNonBlocking(listener->get());
  listener_ = std::move(*listener);
  return std::nullopt;
}

std::optional<std::string> Device::Impl::open() {
  auto base = SocketAddress::resolve(config_.bindAddress, 0);
  if (!base) return base.error();
  // Control (TCP) and discovery (UDP) share one port number; with port 0 the
  // kernel picks the TCP port and discovery must get the same number.
  for (int attempt = 0; attempt < 50; ++attempt) {
    port_ = config_.port;
    if (auto error = openListener()) return error;
    port_ = localAddress(listener_.get()).port();
    auto discovery = bindUdp(base->withPort(port_));
    if (discovery) {
      discovery_ = std::move(*discovery);
      break;
    }
    if (config_.port != 0) return discovery.error();
  }
  if (!discovery_.valid()) return "no port free for both TCP and UDP on " + config_.bindAddress;

  for (auto* socket : {&control_, &video_, &stray_}) {
    auto fd = bindUdp(*base);
    if (!fd) return fd.error();
    *socket = std::move(*fd);
  }
  // Frames of 64 KB datagrams at 30 fps: give the kernel room to queue them.
  int sendBuffer = 4 * 1024 * 1024;
  setsockopt(video_.get(), SOL_SOCKET, SO_SNDBUF, &sendBuffer, sizeof sendBuffer);
  controlPort_ = localAddress(control_.get()).port();
  wake_ = UniqueFd(eventfd(0, EFD_CLOEXEC | EFD_NONBLOCK));
  publishedName_ = name_;
  return std::nullopt;
}

void Device::Impl::requestStop() {
  stopping_ = true;
  uint64_t one = 1;
  if (write(wake_.get(), &one, sizeof one) < 0) {
    // The eventfd cannot be full with one write; the flag is set regardless.
  }
}

void Device::Impl::run() {
  auto now = DeviceClock::now();
  nextPsd_ = now + config_.psdPeriod;
  nextFrame_ = now;
  log("device '" + name_ + "' listening on " + config_.bindAddress + ":" + std::to_string(port_) +
      " (TCP control, UDP discovery), PCD on UDP " + std::to_string(controlPort_));

  std::vector<pollfd> fds;
  while (!stopping_) {
    now = DeviceClock::now();
    runTimers(now);
    sweepClosed();
    publish();

    fds.clear();
    fds.push_back({wake_.get(), POLLIN, 0});
    fds.push_back({discovery_.get(), POLLIN, 0});
    fds.push_back({control_.get(), POLLIN, 0});
    fds.push_back({listener_.valid() ? listener_.get() : -1, POLLIN, 0});
    for (auto& c : connections_) fds.push_back({c.fd.get(), POLLIN, 0});

    int ready = ::poll(fds.data(), fds.size(), pollTimeoutMs(DeviceClock::now()));
    if (ready <= 0) continue;
    now = DeviceClock::now();
    if (fds[1].revents & POLLIN) readDiscovery();
    if (fds[2].revents & POLLIN) readPcd(now);
    if (fds[3].revents & POLLIN) acceptConnection();
    size_t index = 4;
    for (auto& c : connections_) {
      if (index >= fds.size()) break;  // accepted during this turn
      if (fds[index++].revents & (POLLIN | POLLHUP | POLLERR)) readConnection(c);
    }
    // Readers see the effect of a message as soon as its reply is out.
    sweepClosed();
    publish();
  }
  for (auto& [key, stream] : streams_) stream.flush();
  connections_.clear();
  publish();
}

int Device::Impl::pollTimeoutMs(DeviceClock::time_point now) const {
  auto next = std::min(nextPsd_, nextFrame_);
  if (controller_) next = std::min(next, controlDeadline_);
  if (restartDone_) next = std::min(next, *restartDone_);
  auto wait = duration_cast<milliseconds>(next - now).count() + 1;
  return static_cast<int>(std::clamp<long>(wait, 0, 1000));
}

void Device::Impl::runTimers(DeviceClock::time_point now) {
  if (restartDone_ && now >= *restartDone_) {
    restartDone_.reset();
    if (auto error = openListener())
      log("restart failed: " + *error);
    else
      log("restarted as '" + name_ + "'");
  }
  if (controller_ && now >= controlDeadline_) {
    if (auto* c = controller()) {
      enterFailsafe("no PCD for " + std::to_string(config_.pcdTimeout.count()) + " ms");
      closeConnection(*c, "PCD timeout");
    }
  }
  if (now >= nextPsd_) {
    sendStatus();
    nextPsd_ += config_.psdPeriod;
    if (nextPsd_ <= now) nextPsd_ = now + config_.psdPeriod;
  }
  if (now >= nextFrame_) {
    tickFrame(now);
    auto period =
        duration_cast<DeviceClock::duration>(std::chrono::duration<double>(1.0 / config_.fps));
    nextFrame_ += period;
    if (nextFrame_ <= now) nextFrame_ = now + period;  // skip ticks we were too slow for
  }
}

void Device::Impl::tickFrame(DeviceClock::time_point now) {
  if (lastTick_) {
    // The battery drains with throttle (channel 2) away from neutral.
    double seconds = std::chrono::duration<double>(now - *lastTick_).count();
    double throttle = std::abs(static_cast<int>(localOutputs_.pulses[1]) - kPulseNeutral) / 500.0;
    if (localOutputs_.pulses[1] == 0) throttle = 0;
    batteryMillivolts_ = std::max<double>(config_.emptyBatteryMillivolts,
                                          batteryMillivolts_ - seconds * (0.2 + 4.0 * throttle));
  }
  lastTick_ = now;
  if (!scene_) return;
  scene_->advance(now, config_.carControl ? config_.carControl(now) : localOutputs_);
  for (int camera = 0; camera < config_.cameras; ++camera) {
    std::vector<uint8_t> jpeg;
    for (auto& [key, stream] : streams_) {
      if (key.camera != camera) continue;
      if (jpeg.empty()) jpeg = scene_->renderJpeg(camera);
      if (jpeg.empty()) break;
      auto before = stream.stats();
      stream.sendFrame(jpeg);
      ++localStats_.framesSent;
      localStats_.framesSentWhole += stream.stats().framesWhole - before.framesWhole;
      localStats_.datagramsSent += stream.stats().datagrams - before.datagrams;
    }
  }
}

void Device::Impl::sendStatus() {
  Psd psd;
  psd.batteryMillivolts = static_cast<uint16_t>(batteryMillivolts_);
  psd.analogMillivolts = 1650;
  // The digital inputs read back the digital outputs ch9..ch12, as if wired
  // together: a transmitter can see its own PCD take effect.
  for (size_t i = 0; i < 4; ++i) psd.inputs[i] = localOutputs_.pulses[8 + i] > 1500 ? 1 : 0;
  auto frame = encode(psd);
  for (auto& c : connections_) {
    if (!c.started || c.login->statusPort == 0) continue;
    if (sendDatagram(control_.get(), c.peer.withPort(c.login->statusPort), *frame))
      ++localStats_.psdSent;
  }
}

void Device::Impl::acceptConnection() {
  UniqueFd fd(::accept4(listener_.get(), nullptr, nullptr, SOCK_CLOEXEC | SOCK_NONBLOCK));
  if (!fd.valid()) return;
  auto& c = connections_.emplace_back();
  c.peer = peerAddress(fd.get());
  c.fd = std::move(fd);
  c.id = allocateId();
  c.order = nextOrder_++;
  log("connection " + std::to_string(c.id) + " from " + c.peer.toString());
}

uint8_t Device::Impl::allocateId() {
  // IDs 1..255 in turn, skipping those still in use.
  for (int tries = 0; tries < 255; ++tries) {
    uint8_t id = nextId_;
    nextId_ = static_cast<uint8_t>(nextId_ == 255 ? 1 : nextId_ + 1);
    if (!findConnection(id)) return id;
  }
  return 0;
}

void Device::Impl::readConnection(Connection& c) {
  if (c.closing) return;
  ssize_t n = ::recv(c.fd.get(), buffer_.data(), 4096, 0);
  if (n == 0) return closeConnection(c, "closed by the transmitter");
  if (n < 0) {
    if (errno != EAGAIN && errno != EINTR) closeConnection(c, errnoText(errno));
    return;
  }
  c.parser.feed(std::span(buffer_.data(), static_cast<size_t>(n)),
                [&](const Expected<Message, ProtocolError>& result) {
                  if (!c.closing) handleMessage(c, result);
                });
}

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

void Device::Impl::readDiscovery() {
  sockaddr_in from{};
  socklen_t size = sizeof from;
  ssize_t n = ::recvfrom(discovery_.get(), buffer_.data(), buffer_.size(), 0,
                         reinterpret_cast<sockaddr*>(&from), &size);
  if (n <= 0 || restartDone_) return;
  auto message = decode(std::span(buffer_.data(), static_cast<size_t>(n)));
  if (!message || !std::holds_alternative<Bcsd>(*message)) return;
  Bcsa bcsa{config_.hardware, config_.software, name_, config_.serial};
  if (auto frame = encode(bcsa)) sendDatagram(discovery_.get(), SocketAddress(from), *frame);
}

void Device::Impl::readPcd(DeviceClock::time_point now) {
  sockaddr_in from{};
  socklen_t size = sizeof from;
  ssize_t n = ::recvfrom(control_.get(), buffer_.data(), buffer_.size(), 0,
                         reinterpret_cast<sockaddr*>(&from), &size);
  if (n <= 0) return;
  auto message = decode(std::span(buffer_.data(), static_cast<size_t>(n)));
  Connection* current = controller();
  // On loopback every transmitter shares one address: the source host is
  // all a PCD (which carries no connection ID) can be checked against.
  if (!message || !std::holds_alternative<Pcd>(*message) || !current ||
      !current->peer.sameHost(SocketAddress(from))) {
    ++localStats_.pcdRejected;
    return;
  }
  if (lastPcd_) {
    auto gap = duration_cast<milliseconds>(now - *lastPcd_);
    localStats_.maxPcdGap = std::max(localStats_.maxPcdGap, gap);
  }
  lastPcd_ = now;
  controlDeadline_ = now + config_.pcdTimeout;
  {
    std::lock_guard lock(mutex_);
    pcdArrivals_.push_back(now);
    if (pcdArrivals_.size() > 4096) pcdArrivals_.pop_front();
  }
  ++localStats_.pcdReceived;
  if (localOutputs_.failsafe) log("PCD received: leaving failsafe");
  localOutputs_.pulses = std::get<Pcd>(*message).values;
  localOutputs_.failsafe = false;
}

void Device::Impl::enterFailsafe(const std::string& why) {
  if (localOutputs_.failsafe) return;
  for (size_t i = 0; i < kChannelCount; ++i)
    if (failsafe_[i] != kFailsafeHoldLast) localOutputs_.pulses[i] = failsafe_[i];
  localOutputs_.failsafe = true;
  ++localStats_.failsafeEntries;
  log("failsafe: " + why);
}

void Device::Impl::closeConnection(Connection& c, std::string reason) {
  if (c.closing) return;
  c.closing = true;
  c.closeReason = std::move(reason);
}

void Device::Impl::sweepClosed() {
  bool controllerLeft = false;
  for (auto it = connections_.begin(); it != connections_.end();) {
    if (!it->closing) {
      ++it;
      continue;
    }
    log("connection " + std::to_string(it->id) + " closed: " + it->closeReason);
    for (auto stream = streams_.begin(); stream != streams_.end();) {
      if (stream->first.connection == it->id) {
        stream->second.flush();
        stream = streams_.erase(stream);
      } else {
        ++stream;
      }
    }
    if (controller_ == it->id) {
      controllerLeft = true;
      controller_.reset();
    }
    it = connections_.erase(it);
  }
  if (!controllerLeft) return;
  enterFailsafe("the controlling transmitter left");
  // Hand-over: highest priority, then the lowest connection ID.
  Connection* next = nullptr;
  for (auto& c : connections_) {
    if (!c.started) continue;
    if (!next || c.login->priority > next->login->priority ||
        (c.login->priority == next->login->priority && c.id < next->id))
      next = &c;
  }
  if (next) giveControl(*next);
}

void Device::Impl::restart() {
  // Called while the connection list is being walked: the connections close
  // at the end of this loop turn.
  for (auto& c : connections_) closeConnection(c, "firmware update");
  controller_.reset();
  enterFailsafe("restarting");
  listener_.reset();
  if (!pendingName_.empty()) name_ = pendingName_;
  ++localStats_.restarts;
  restartDone_ = DeviceClock::now() + config_.restartTime;
}

void Device::Impl::sendMessage(Connection& c, const Message& message) {
  auto frame = encode(message);
  if (!frame) {
    log("not sent: " + frame.error().message());
    return;
  }
  // The transmitter must keep reading; one that stalls long enough to fill
  // the socket buffer is cut off rather than buffered without bound.
  ssize_t sent = ::send(c.fd.get(), frame->data(), frame->size(), MSG_NOSIGNAL | MSG_DONTWAIT);
  if (sent != static_cast<ssize_t>(frame->size()))
    closeConnection(c, sent < 0 ? errnoText(errno) : "transmitter not reading");
}

void Device::Impl::sendError(Connection& c, uint8_t command, ErrorCode code) {
  ++localStats_.errSent;
  sendMessage(c, Err{command, static_cast<uint16_t>(code)});
}

void Device::Impl::publish() {
  localStats_.activeStreams = streams_.size();
  std::lock_guard lock(mutex_);
  stats_ = localStats_;
  outputs_ = localOutputs_;
  publishedName_ = name_;
}

Expected<std::unique_ptr<Device>, std::string> Device::start(DeviceConfig config,
                                                             std::shared_ptr<DeviceScene> scene,
                                                             Logger logger) {
  if (config.cameras < 1 || config.cameras > 255)
    return unexpected(std::string("cameras must be 1..255"));
  if (config.fps <= 0 || config.fps > 240)
    return unexpected(std::string("fps must be in (0, 240]"));
  auto impl = std::make_unique<Impl>(std::move(config), std::move(scene), std::move(logger));
  if (auto error = impl->open()) return unexpected(*error);
  impl->thread_ = std::thread([raw = impl.get()] { raw->run(); });
  return std::unique_ptr<Device>(new Device(std::move(impl)));
}

Device::Device(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}

Device::~Device() { stop(); }

void Device::stop() {
  if (!impl_->thread_.joinable()) return;
  impl_->requestStop();
  impl_->thread_.join();
}

uint16_t Device::port() const { return impl_->port_; }
uint16_t Device::controlPort() const { return impl_->controlPort_; }

DeviceStats Device::stats() const {
  std::lock_guard lock(impl_->mutex_);
  return impl_->stats_;
}

ChannelOutputs Device::outputs() const {
  std::lock_guard lock(impl_->mutex_);
  return impl_->outputs_;
}

std::vector<DeviceClock::time_point> Device::pcdArrivals() const {
  std::lock_guard lock(impl_->mutex_);
  return {impl_->pcdArrivals_.begin(), impl_->pcdArrivals_.end()};
}

std::string Device::name() const {
  std::lock_guard lock(impl_->mutex_);
  return impl_->publishedName_;
}

}  // namespace wircam::wirc
