#include "wirc/transmitter_session.h"

#include <netinet/tcp.h>
#include <sys/epoll.h>
#include <sys/socket.h>

#include <algorithm>
#include <array>
#include <cerrno>
#include <functional>
#include <map>
#include <mutex>

#include "common/priority_inheriting_mutex.h"
#include "link/alarm.h"
#include "link/command_pacer.h"
#include "link/event_loop.h"
#include "link/link_registry.h"
#include "link/shared_settings.h"
#include "wirc/channel_list.h"
#include "wirc/discovery.h"
#include "wirc/login_machine.h"
#include "wirc/message_stream_parser.h"

namespace wircam::wirc {

namespace {

using link::Clock;
using link::EventLoop;
using std::chrono::milliseconds;

// One read callback takes at most this much, so a flooding device cannot
// starve the other links of the event loop.
constexpr size_t kMaxReadPerWake = 64 * 1024;

// FCFG's special values are not pulses; PCD sends neutral for them.
link::Pulses pcdFailsafe(const ChannelValues& failsafe) {
  link::Pulses pulses = failsafe;
  for (auto& pulse : pulses)
    if (pulse < kPulseMin || pulse > kPulseMax) pulse = kPulseNeutral;
  return pulses;
}

link::PacerConfig pacerConfig(const SessionConfig& config) {
  return {.keepalive = config.keepalive,
          .minInterval = link::intervalOf(config.pcdRate),
          .ttl = config.commandTtl,
          .failsafe = pcdFailsafe(config.failsafe),
          .keepaliveEarly = EventLoop::kCoalesce};
}

// A setting several users of one link may give: how it reads in a message,
// how it is taken over, and whether the device must hear it in a new login.
struct SharedSetting {
  const char* name;
  std::function<std::string(const SessionConfig&)> text;
  std::function<void(SessionConfig&, const SessionConfig&)> adopt;
  bool needsLogin;
};

template <typename T, typename Text>
SharedSetting shared(const char* name, T SessionConfig::*field, Text text, bool needsLogin) {
  return {name, [field, text](const SessionConfig& c) { return text(c.*field); },
          [field](SessionConfig& to, const SessionConfig& from) { to.*field = from.*field; },
          needsLogin};
}

std::string quoted(const std::string& text) { return "'" + text + "'"; }
std::string integer(uint8_t value) { return std::to_string(value); }
std::string number(double value) {
  std::string text = std::to_string(value);
  text.erase(text.find_last_not_of('0') + 1);
  if (text.back() == '.') text.pop_back();
  return text;
}
std::string ms(milliseconds value) { return std::to_string(value.count()) + " ms"; }
std::string flag(bool value) { return value ? "true" : "false"; }
std::string count(uint32_t value) { return std::to_string(value); }

const std::vector<SharedSetting>& sharedSettings() {
  static const std::vector<SharedSetting> settings = {
      shared("transmitter-name", &SessionConfig::transmitterName, quoted, true),
      shared("priority", &SessionConfig::priority, integer, true),
      shared("periods", &SessionConfig::periods, formatChannelList, true),
      shared("failsafe", &SessionConfig::failsafe, formatChannelList, true),
      shared("pcd-rate", &SessionConfig::pcdRate, number, false),
      shared("keepalive", &SessionConfig::keepalive, ms, false),
      shared("lost-timeout", &SessionConfig::commandTtl, ms, false),
      shared("login-timeout", &SessionConfig::loginTimeout, ms, false),
      shared("link-timeout", &SessionConfig::linkTimeout, ms, false),
      shared("reconnect", &SessionConfig::reconnect, flag, false),
      shared("max-bad-messages", &SessionConfig::maxBadMessages, count, false),
  };
  return settings;
}

}  // namespace

std::string SessionConfig::key() const {
  if (!host.empty()) return host + ":" + std::to_string(port);
  return "discover:" + device + "@" + discoveryAddress + ":" + std::to_string(port);
}

const char* errorCodeMeaning(uint16_t code) {
  switch (static_cast<ErrorCode>(code)) {
    case ErrorCode::None:
      return "no error";
    case ErrorCode::Format:
      return "format error";
    case ErrorCode::Denied:
      return "denied";
    case ErrorCode::System:
      return "system error";
    case ErrorCode::Save:
      return "could not save";
    case ErrorCode::Unauthorised:
      return "unauthorised: not logged in";
    case ErrorCode::Busy:
      return "busy: the device already has a connection from this address";
  }
  return "unknown error code";
}

// The I/O around the LoginMachine: the sockets and timers on the event
// loop, and the mutex every thread takes to reach the machine.
class TransmitterSession::Impl {
 public:
  Impl(SessionConfig config, link::LinkListeners& listeners, EventLoop& loop);
  ~Impl();

  // Hands an event to the machine (under the mutex) and carries out what it
  // asks for. On the loop thread, the deadline timer follows the machine's.
  template <typename Event>
  void handle(Event event) {
    LoginActions actions;
    std::optional<Clock::time_point> deadline;
    {
      MutexLock lock(mutex_);
      actions = event(machine_);
      deadline = machine_.nextDeadline();
      followStatusReports();
    }
    changed_.notifyAll();
    if (loop_.inLoopThread()) {
      if (deadline)
        loop_.arm(deadlineTimer_, *deadline);
      else
        loop_.disarm(deadlineTimer_);
    }
    for (auto& action : actions) perform(std::move(action));
  }

  void perform(LoginAction action);
  void discover(const SocketAddress& destination);
  void connect(const SocketAddress& device);
  void onTcp(uint32_t events);
  void readTcp();
  void onDiscoveryAnswer();
  void readStatusReports();
  void onPacerAlarm();
  // While steering, a keepalive leaves at least every `keepalive` (100 ms
  // by default, never off; on a stream's turn or the pacer's alarm), and
  // the status reports waiting are read as it leaves: the loop wakes for
  // none of them (two a second, at CIF/15 about a tenth of the receiving
  // process's CPU). Otherwise the loop wakes for each. Under mutex_.
  void followStatusReports() {
    bool wake = !steering();
    if (wake == loopWakesForStatus_) return;
    loop_.setEvents(psdWatch_, wake ? uint32_t{EPOLLIN} : 0u);
    loopWakesForStatus_ = wake;
  }
  // Whether commands reach the vehicle now: logged in, holding the control
  // right, the device's address known. Under mutex_.
  bool steering() const {
    const auto& status = machine_.status();
    return status.state == link::LinkState::Live && status.hasControl && machine_.controlAddress();
  }
  void closeConnection();
  bool sendControl(const Message& message);
  void sendPcd(const link::Pulses& pulses);

  EventLoop& loop_;
  link::LinkListeners& listeners_;
  UniqueFd psdSocket_;  // PSD arrive here
  UniqueFd pcdSocket_;  // PCD leave from here
  EventLoop::Id psdWatch_ = 0;
  EventLoop::Id deadlineTimer_ = 0;
  // Of its own (link/alarm.h): moved by the streams' threads on their turns.
  link::Alarm pacerAlarm_;

  // Loop thread only.
  UniqueFd discovery_;
  EventLoop::Id discoveryWatch_ = 0;
  EventLoop::Id tcpWatch_ = 0;
  MessageStreamParser parser_;  // one per connection, for its whole life

  // Guards the machine and the pacer; never held while sending, waiting or
  // emitting. Both locks are shared by the loop with the streams' threads,
  // so they lend priority (event_loop.h).
  mutable PriorityInheritingMutex mutex_;
  PriorityInheritingCondition changed_;
  LoginMachine machine_;
  link::CommandPacer pacer_;
  bool loopWakesForStatus_ = true;

  // The TCP connection; sendMutex_ serialises writers from any thread.
  PriorityInheritingMutex sendMutex_;
  UniqueFd tcp_;
};

namespace {
uint16_t boundPort(const UniqueFd& socket) {
  return socket.valid() ? localAddress(socket.get()).port() : 0;
}
UniqueFd boundUdp() {
  auto fd = bindUdp(*SocketAddress::resolve("", 0));
  if (!fd) return {};
  setNonBlocking(fd->get());
  return std::move(*fd);
}
}  // namespace

TransmitterSession::Impl::Impl(SessionConfig config, link::LinkListeners& listeners,
                               EventLoop& loop)
    : loop_(loop),
      listeners_(listeners),
      psdSocket_(boundUdp()),
      pcdSocket_(boundUdp()),
      pacerAlarm_(loop, [this] { onPacerAlarm(); }),
      machine_(config, boundPort(psdSocket_), Clock::now()),
      pacer_(pacerConfig(config)) {
  psdWatch_ = loop_.watch(psdSocket_.get(), EPOLLIN, [this](uint32_t) { readStatusReports(); });
  // The link's timeout looks at the reports waiting too, not only at those
  // a keepalive took with it.
  deadlineTimer_ = loop_.addTimer([this] {
    readStatusReports();
    handle([](LoginMachine& m) { return m.onDeadline(Clock::now()); });
  });
  loop_.arm(deadlineTimer_, Clock::now());
}

TransmitterSession::Impl::~Impl() {
  // On the loop thread, so no callback of this session runs during or after.
  loop_.invoke([this] {
    // Log out: stop the streams this session started (best effort, no wait).
    handle([](LoginMachine& m) { return m.close(); });
    for (auto id : {psdWatch_, deadlineTimer_}) loop_.remove(id);
    pacerAlarm_.stop();
  });
}

void TransmitterSession::Impl::perform(LoginAction action) {
  if (auto* send = std::get_if<login::Send>(&action)) {
    sendControl(send->message);
  } else if (auto* emit = std::get_if<login::Emit>(&action)) {
    listeners_.emit(emit->event);
  } else if (auto* discovery = std::get_if<login::Discover>(&action)) {
    discover(discovery->destination);
  } else if (auto* connection = std::get_if<login::Connect>(&action)) {
    connect(connection->device);
  } else if (std::holds_alternative<login::Close>(action)) {
    closeConnection();
  } else if (auto* aim = std::get_if<login::AimCommands>(&action)) {
    // Connected to the device's control port: a send skips the route
    // lookup a sendto pays, many times a second.
    ::connect(pcdSocket_.get(), aim->control.raw(), aim->control.size());
  } else if (std::holds_alternative<login::StartCommands>(action)) {
    MutexLock lock(mutex_);
    pacer_.restart();
    pacerAlarm_.set(Clock::now());
  }
}

void TransmitterSession::Impl::discover(const SocketAddress& destination) {
  auto socket = sendDiscoveryRequest(destination);
  if (!socket)
    return handle(
        [&](LoginMachine& m) { return m.onConnectionLost(socket.error(), Clock::now()); });
  discovery_ = std::move(*socket);
  discoveryWatch_ =
      loop_.watch(discovery_.get(), EPOLLIN, [this](uint32_t) { onDiscoveryAnswer(); });
}

void TransmitterSession::Impl::onDiscoveryAnswer() {
  while (discovery_.valid()) {
    auto answer = readDiscoveryAnswer(discovery_.get());
    if (!answer) return;
    handle([&](LoginMachine& m) { return m.onDiscoveryAnswer(std::move(*answer), Clock::now()); });
  }
}

void TransmitterSession::Impl::connect(const SocketAddress& device) {
  auto fd = startConnectTcp(device);
  if (!fd)
    return handle([&](LoginMachine& m) { return m.onConnectionLost(fd.error(), Clock::now()); });
  int fdNumber = fd->get();
  {
    MutexLock lock(sendMutex_);
    tcp_ = std::move(*fd);
  }
  // TCP's own keepalive as well, for a device that vanishes while PSD are
  // off (the link timeout normally notices first).
  int on = 1, idle = 2, interval = 1, probes = 3;
  setsockopt(fdNumber, SOL_SOCKET, SO_KEEPALIVE, &on, sizeof on);
  setsockopt(fdNumber, IPPROTO_TCP, TCP_KEEPIDLE, &idle, sizeof idle);
  setsockopt(fdNumber, IPPROTO_TCP, TCP_KEEPINTVL, &interval, sizeof interval);
  setsockopt(fdNumber, IPPROTO_TCP, TCP_KEEPCNT, &probes, sizeof probes);
  parser_ = MessageStreamParser();
  tcpWatch_ = loop_.watch(fdNumber, EPOLLOUT, [this](uint32_t events) { onTcp(events); });
}

void TransmitterSession::Impl::onTcp(uint32_t events) {
  bool connecting;
  {
    MutexLock lock(mutex_);
    connecting = machine_.phase() == LoginMachine::Phase::Connecting;
  }
  if (!connecting) return readTcp();
  int error = pendingError(tcp_.get());
  if (error != 0 || (events & (EPOLLERR | EPOLLHUP))) {
    std::string device;
    {
      MutexLock lock(mutex_);
      device = machine_.device() ? machine_.device()->toString() : machine_.config().host;
    }
    std::string why = "cannot connect to " + device + ": " +
                      errnoText(error ? error : ECONNREFUSED) +
                      " (is the device on and is that its address?)";
    return handle([&](LoginMachine& m) { return m.onConnectionLost(why, Clock::now()); });
  }
  loop_.setEvents(tcpWatch_, EPOLLIN);
  handle([](LoginMachine& m) { return m.onConnected(Clock::now()); });
}

void TransmitterSession::Impl::readTcp() {
  auto lost = [this](const std::string& why) {
    handle([&](LoginMachine& m) { return m.onConnectionLost(why, Clock::now()); });
  };
  std::array<uint8_t, 4096> buffer;
  for (size_t taken = 0; taken < kMaxReadPerWake && tcp_.valid(); taken += buffer.size()) {
    ssize_t n = ::recv(tcp_.get(), buffer.data(), buffer.size(), MSG_DONTWAIT);
    if (n == 0) return lost("the device closed the connection");
    if (n < 0) {
      if (errno == EAGAIN || errno == EWOULDBLOCK) return;
      if (errno == EINTR) continue;
      return lost("connection to the device lost: " + errnoText(errno));
    }
    parser_.feed(std::span(buffer.data(), static_cast<size_t>(n)),
                 [&](const Expected<Message, ProtocolError>& result) {
                   // Malformed input is counted by the parser and dropped;
                   // nothing more once a message closed the connection.
                   if (result && tcp_.valid())
                     handle([&](LoginMachine& m) { return m.onMessage(*result, Clock::now()); });
                 });
    if (!tcp_.valid()) return;
    handle([&](LoginMachine& m) { return m.onParserStats(parser_.stats(), Clock::now()); });
  }
}

void TransmitterSession::Impl::closeConnection() {
  if (tcpWatch_) loop_.remove(tcpWatch_);
  tcpWatch_ = 0;
  if (discoveryWatch_) loop_.remove(discoveryWatch_);
  discoveryWatch_ = 0;
  discovery_.reset();
  MutexLock lock(sendMutex_);
  if (tcp_.valid()) ::shutdown(tcp_.get(), SHUT_RDWR);
  tcp_.reset();
}

bool TransmitterSession::Impl::sendControl(const Message& message) {
  auto frame = encode(message);
  if (!frame) return false;
  MutexLock lock(sendMutex_);
  if (!tcp_.valid()) return false;
  // Non-blocking: a device that stops reading its connection is not waited
  // for; the short write shows up as a lost connection on the next read.
  ssize_t sent = ::send(tcp_.get(), frame->data(), frame->size(), MSG_NOSIGNAL);
  if (sent != static_cast<ssize_t>(frame->size())) ::shutdown(tcp_.get(), SHUT_RDWR);
  return sent == static_cast<ssize_t>(frame->size());
}

void TransmitterSession::Impl::sendPcd(const link::Pulses& pulses) {
  auto frame = encode(Pcd{pulses});  // the pacer clamps: always valid
  if (frame && ::send(pcdSocket_.get(), frame->data(), frame->size(), MSG_NOSIGNAL) ==
                   static_cast<ssize_t>(frame->size())) {
    MutexLock lock(mutex_);
    machine_.countCommandSent();
  }
  readStatusReports();  // those that came since the last (followStatusReports)
}

void TransmitterSession::Impl::readStatusReports() {
  std::array<uint8_t, 64> buffer;
  // At most a few per wake-up: a flood on this port cannot starve the loop.
  receiveDatagrams(psdSocket_.get(), buffer, 16,
                   [this](std::span<const uint8_t> bytes, const SocketAddress& from) {
                     auto message = decode(bytes);
                     if (!message || !std::holds_alternative<Psd>(*message)) return;
                     handle([&](LoginMachine& m) {
                       return m.onStatusReport(from, std::get<Psd>(*message), Clock::now());
                     });
                   });
}

void TransmitterSession::Impl::onPacerAlarm() {
  auto now = Clock::now();
  std::optional<link::Pulses> due;
  {
    MutexLock lock(mutex_);
    if (!steering()) return;
    due = pacer_.poll(now);
    pacerAlarm_.set(pacer_.nextWindow(now));
  }
  if (due) sendPcd(*due);
}

// ---------------------------------------------------------------------------

Expected<std::shared_ptr<TransmitterSession>, std::string> TransmitterSession::acquire(
    const SessionConfig& config, const std::string& user, EventLoop& loop) {
  if (config.keepalive > kMaxKeepalive || config.keepalive.count() <= 0)
    return unexpected("keepalive " + ms(config.keepalive) + " is outside 1.." + ms(kMaxKeepalive) +
                      ": it must stay well below the device's PCD timeout (200..2000 ms)");
  if (config.linkTimeout.count() > 0 && config.linkTimeout < milliseconds(2 * kPsdPeriodMs))
    return unexpected("link-timeout " + ms(config.linkTimeout) + " is shorter than two status " +
                      "reports (" + ms(milliseconds(2 * kPsdPeriodMs)) + "): use 0 (off) or more");
  if (auto tl = encode(Tl{.name = config.transmitterName}); !tl)
    return unexpected("transmitter-name " + quoted(config.transmitterName) +
                      " cannot be sent: " + tl.error().message());

  // The settings this user gave; a shared link takes over those nobody
  // else gave (logging in again where one needs it).
  link::SettingValues given;
  for (const auto& setting : sharedSettings())
    if (config.given.count(setting.name)) given[setting.name] = setting.text(config);
  static link::LinkRegistry<TransmitterSession> registry;
  bool relogin = false;
  auto session = registry.acquireChangeable(
      loop, config.key(), given, user,
      [&]() -> Expected<std::shared_ptr<TransmitterSession>, std::string> {
        return std::shared_ptr<TransmitterSession>(new TransmitterSession(config, loop));
      },
      [](TransmitterSession& shared) {
        MutexLock lock(shared.impl_->mutex_);
        link::SettingValues current;
        for (const auto& setting : sharedSettings())
          current[setting.name] = setting.text(shared.impl_->machine_.config());
        return current;
      },
      [&](TransmitterSession& shared, const std::vector<std::string>& changes) {
        auto* impl = shared.impl_.get();
        MutexLock lock(impl->mutex_);
        auto& linkConfig = impl->machine_.config();
        for (const auto& setting : sharedSettings()) {
          if (std::find(changes.begin(), changes.end(), setting.name) == changes.end()) continue;
          setting.adopt(linkConfig, config);
          relogin = relogin || setting.needsLogin;
        }
        impl->pacer_ = link::CommandPacer(pacerConfig(linkConfig));
      });
  if (session && relogin) {
    auto* impl = (*session)->impl_.get();
    impl->loop_.invoke([impl, &user] {
      impl->handle([&](LoginMachine& m) {
        return m.relogin("logging in again with the settings of " + user, Clock::now());
      });
    });
  }
  return session;
}

TransmitterSession::TransmitterSession(const SessionConfig& config, EventLoop& loop)
    : impl_(std::make_unique<Impl>(config, listeners_, loop)) {}

TransmitterSession::~TransmitterSession() = default;

std::optional<std::string> TransmitterSession::waitLoggedIn(milliseconds timeout) {
  MutexLock lock(impl_->mutex_);
  const auto& machine = impl_->machine_;
  bool done = impl_->changed_.waitFor(impl_->mutex_, timeout, [&] {
    return machine.status().state == link::LinkState::Live || machine.failedAttempts() > 0;
  });
  if (machine.status().state == link::LinkState::Live) return std::nullopt;
  if (!done) return "no login within " + std::to_string(timeout.count()) + " ms";
  return machine.status().reason;
}

link::LinkStatus TransmitterSession::status() const { return sessionStatus(); }

SessionStatus TransmitterSession::sessionStatus() const {
  MutexLock lock(impl_->mutex_);
  return impl_->machine_.status();
}

std::optional<SocketAddress> TransmitterSession::deviceAddress() const {
  MutexLock lock(impl_->mutex_);
  return impl_->machine_.device();
}

void TransmitterSession::startStream(uint8_t camera, uint16_t port) {
  impl_->handle([&](LoginMachine& m) { return m.startStream(camera, port); });
}

void TransmitterSession::stopStream(uint8_t camera) {
  impl_->handle([&](LoginMachine& m) { return m.stopStream(camera); });
}

void TransmitterSession::setCommand(const link::Pulses& pulses) {
  auto now = Clock::now();
  std::optional<link::Pulses> due;
  {
    MutexLock lock(impl_->mutex_);
    due = impl_->pacer_.offer(pulses, now);
    if (!impl_->steering()) return;  // kept for when the control right comes
    impl_->pacerAlarm_.set(impl_->pacer_.nextWindow(now));
  }
  // A change leaves now, from this thread: no wait for a tick.
  if (due) impl_->sendPcd(*due);
}

void TransmitterSession::shareTurn(Clock::duration untilNextTurn) {
  auto now = Clock::now();
  std::optional<link::Pulses> due;
  {
    MutexLock lock(impl_->mutex_);
    if (!impl_->steering()) return;
    due = impl_->pacer_.pollAhead(now, untilNextTurn);
    if (!due) return;  // the alarm stands
    // Later than it stood, so the loop sleeps on; and at the deadline
    // itself, not the window's first shared tick, which would go off
    // before the next turn could send the next keepalive.
    impl_->pacerAlarm_.set(impl_->pacer_.nextDeadline(now));
  }
  impl_->sendPcd(*due);
}

void TransmitterSession::requestControl() {
  uint8_t id;
  {
    MutexLock lock(impl_->mutex_);
    id = impl_->machine_.status().connectionId;
  }
  requestControlFor(id);
}

void TransmitterSession::requestControlFor(uint8_t connectionId) {
  impl_->handle([&](LoginMachine& m) { return m.requestControl(connectionId); });
}

std::optional<std::vector<TransmitterInfo>> TransmitterSession::listTransmitters(
    milliseconds timeout) {
  bool sent = false;
  impl_->handle([&](LoginMachine& m) {
    auto actions = m.listTransmitters();
    sent = !actions.empty();
    return actions;
  });
  if (!sent) return std::nullopt;
  MutexLock lock(impl_->mutex_);
  const auto& machine = impl_->machine_;
  if (!impl_->changed_.waitFor(impl_->mutex_, timeout,
                               [&] { return machine.transmitterListComplete(); }))
    return std::nullopt;
  return machine.transmitters();
}

std::optional<Err> TransmitterSession::sendConfiguration(const Message& message,
                                                         milliseconds timeout) {
  uint8_t command = commandCode(message);
  bool sent = false;
  impl_->handle([&](LoginMachine& m) {
    m.clearErrors();
    auto actions = m.send(message);
    sent = !actions.empty();
    return actions;
  });
  if (!sent) return Err{command, static_cast<uint16_t>(ErrorCode::System)};
  MutexLock lock(impl_->mutex_);
  std::optional<Err> answer;
  impl_->changed_.waitFor(impl_->mutex_, timeout, [&] {
    for (const auto& err : impl_->machine_.errors())
      if (err.command == command) answer = err;
    return answer.has_value();
  });
  return answer;
}

}  // namespace wircam::wirc
