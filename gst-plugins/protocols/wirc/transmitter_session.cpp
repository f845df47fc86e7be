#include "wirc/transmitter_session.h"

#include <netinet/tcp.h>
#include <sys/epoll.h>
#include <sys/socket.h>

#include <algorithm>
#include <array>
#include <cerrno>
#include <condition_variable>
#include <functional>
#include <map>
#include <mutex>

#include "link/command_pacer.h"
#include "link/event_loop.h"
#include "wirc/channel_list.h"
#include "wirc/discovery.h"
#include "wirc/message_stream_parser.h"

namespace wircam::wirc {

namespace {

using link::Clock;
using link::EventLoop;
using std::chrono::milliseconds;

constexpr milliseconds kFirstBackoff{200};
constexpr milliseconds kMaxBackoff{5000};
// A login is only a success once the link has stayed up this long: a device
// that misbehaves right after each login (a flood, a refusal of the stream)
// would otherwise be logged in to every kFirstBackoff for ever.
constexpr milliseconds kHealthyLink{10000};
// Discovery listens this long (at most) for the devices to answer.
constexpr milliseconds kDiscoveryWindow{1000};
// One read callback takes at most this much, so a flooding device cannot
// starve the other links of the event loop.
constexpr size_t kMaxReadPerWake = 64 * 1024;
constexpr milliseconds kRejectSummaryPeriod{1000};

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

class TransmitterSession::Impl {
 public:
  Impl(SessionConfig config, link::LinkListeners& listeners);
  ~Impl();

  enum class Phase { Waiting, Discovering, Connecting, LoggingIn, LoggedIn, Closed };

  // Loop thread: one login attempt, step by step.
  void onAttemptTimer();
  void beginAttempt();
  void onDiscoveryAnswer();
  void finishDiscovery();
  void startConnect(const SocketAddress& device, const std::string& name);
  void onTcp(uint32_t events);
  void onConnected();
  void onLoggedIn(const Wst& wst);
  void handle(const Message& message);
  // Closes the connection and reports why; tries again after the backoff
  // (or not at all with reconnect off). A new login for new settings tries
  // again at once and is no loss.
  enum class Retry { AfterBackoff, AtOnceForNewSettings };
  void fail(const std::string& why, Retry retry = Retry::AfterBackoff);
  void closeConnection();
  void onPsd();
  void onPacerTimer();
  void onStatusTimer();
  void countRejected(Clock::time_point now);

  bool sendControl(const Message& message);
  void sendPcd(const link::Pulses& pulses);
  void publish(std::vector<link::LinkEvent> events);

  EventLoop& loop_ = EventLoop::shared();
  link::LinkListeners& listeners_;
  UniqueFd psdSocket_;  // PSD arrive here
  UniqueFd pcdSocket_;  // PCD leave from here
  EventLoop::Id psdWatch_ = 0;
  EventLoop::Id attemptTimer_ = 0;
  EventLoop::Id pacerTimer_ = 0;
  EventLoop::Id statusTimer_ = 0;

  // Loop thread only.
  Phase phase_ = Phase::Waiting;
  Clock::time_point attemptDeadline_;
  milliseconds backoff_ = kFirstBackoff;
  std::optional<Clock::time_point> liveSince_;  // the current login's
  UniqueFd discovery_;
  EventLoop::Id discoveryWatch_ = 0;
  std::vector<DiscoveredDevice> found_;
  EventLoop::Id tcpWatch_ = 0;
  MessageStreamParser parser_;           // one per connection, for its whole life
  Clock::time_point lastHeard_;          // login, or the last PSD
  uint64_t rejectedThisConnection_ = 0;  // malformed messages, weighted
  uint64_t rejectedUnreported_ = 0;      // since the last summary
  StreamParserStats reported_;           // parser counters at the last summary
  Clock::time_point lastSummary_;

  // Guards everything below; never held while sending, waiting or emitting.
  mutable std::mutex mutex_;
  std::condition_variable changed_;
  SessionConfig config_;
  std::map<std::string, std::string> owners_;  // setting name → the user who gave it
  SessionStatus status_;
  std::optional<SocketAddress> device_;
  std::optional<SocketAddress> controlAddress_;
  std::map<uint8_t, uint16_t> streamPorts_;
  link::CommandPacer pacer_;
  std::vector<TransmitterInfo> transmitters_;
  bool listComplete_ = false;
  std::vector<Err> errors_;
  uint64_t failedAttempts_ = 0;
  int controlRequests_ = 0;  // AREQ sent and not answered yet

  // The TCP connection; sendMutex_ serialises writers from any thread.
  std::mutex sendMutex_;
  UniqueFd tcp_;
};

TransmitterSession::Impl::Impl(SessionConfig config, link::LinkListeners& listeners)
    : listeners_(listeners), config_(std::move(config)), pacer_(pacerConfig(config_)) {
  if (auto fd = bindUdp(*SocketAddress::resolve("", 0))) psdSocket_ = std::move(*fd);
  if (auto fd = bindUdp(*SocketAddress::resolve("", 0))) pcdSocket_ = std::move(*fd);
  setNonBlocking(psdSocket_.get());
  setNonBlocking(pcdSocket_.get());
  psdWatch_ = loop_.watch(psdSocket_.get(), EPOLLIN, [this](uint32_t) { onPsd(); });
  pacerTimer_ = loop_.addTimer([this] { onPacerTimer(); });
  statusTimer_ = loop_.addTimer([this] { onStatusTimer(); });
  attemptTimer_ = loop_.addTimer([this] { onAttemptTimer(); });
  loop_.arm(attemptTimer_, Clock::now());
}

TransmitterSession::Impl::~Impl() {
  // On the loop thread, so no callback of this session runs during or after.
  loop_.invoke([this] {
    phase_ = Phase::Closed;
    std::map<uint8_t, uint16_t> streams;
    {
      std::lock_guard lock(mutex_);
      streams = streamPorts_;
    }
    // Log out: stop the streams this session started (best effort, no wait).
    for (const auto& [camera, port] : streams) sendControl(Est{camera});
    closeConnection();
    for (auto id : {psdWatch_, attemptTimer_, pacerTimer_, statusTimer_}) loop_.remove(id);
  });
}

void TransmitterSession::Impl::publish(std::vector<link::LinkEvent> events) {
  for (const auto& event : events) listeners_.emit(event);
}

bool TransmitterSession::Impl::sendControl(const Message& message) {
  auto frame = encode(message);
  if (!frame) return false;
  std::lock_guard lock(sendMutex_);
  if (!tcp_.valid()) return false;
  // Non-blocking: a device that stops reading its connection is not waited
  // for; the short write shows up as a lost connection on the next read.
  ssize_t sent = ::send(tcp_.get(), frame->data(), frame->size(), MSG_NOSIGNAL);
  if (sent != static_cast<ssize_t>(frame->size())) ::shutdown(tcp_.get(), SHUT_RDWR);
  return sent == static_cast<ssize_t>(frame->size());
}

void TransmitterSession::Impl::sendPcd(const link::Pulses& pulses) {
  auto frame = encode(Pcd{pulses});  // the pacer clamps: always valid
  // The socket is connected to the device's control port at login: a send
  // skips the route lookup a sendto pays, many times a second.
  if (frame && ::send(pcdSocket_.get(), frame->data(), frame->size(), MSG_NOSIGNAL) ==
                   static_cast<ssize_t>(frame->size())) {
    std::lock_guard lock(mutex_);
    ++status_.commandsSent;
  }
}

void TransmitterSession::Impl::onAttemptTimer() {
  switch (phase_) {
    case Phase::Waiting:
      return beginAttempt();
    case Phase::Discovering:
      return finishDiscovery();
    case Phase::Connecting:
      return fail("cannot connect to " + (device_ ? device_->toString() : config_.host) +
                  " within the login timeout (is the device on and is that its address?)");
    case Phase::LoggingIn:
      return fail("no WST from " + (device_ ? device_->toString() : config_.host) +
                  " within the login timeout (the device accepted the connection but did not "
                  "answer the login)");
    case Phase::LoggedIn:
    case Phase::Closed:
      return;
  }
}

void TransmitterSession::Impl::beginAttempt() {
  SessionConfig config;
  {
    std::lock_guard lock(mutex_);
    config = config_;
  }
  attemptDeadline_ = Clock::now() + config.loginTimeout;
  if (!config.host.empty()) {
    auto resolved = SocketAddress::resolve(config.host, config.port);
    if (!resolved) return fail(resolved.error());
    return startConnect(*resolved, "");
  }
  auto destination = SocketAddress::resolve(config.discoveryAddress, config.port);
  if (!destination) return fail(destination.error());
  auto socket = sendDiscoveryRequest(*destination);
  if (!socket) return fail(socket.error());
  discovery_ = std::move(*socket);
  found_.clear();
  phase_ = Phase::Discovering;
  discoveryWatch_ =
      loop_.watch(discovery_.get(), EPOLLIN, [this](uint32_t) { onDiscoveryAnswer(); });
  loop_.arm(attemptTimer_,
            std::min(attemptDeadline_,
                     Clock::now() + std::min(config.loginTimeout / 2, kDiscoveryWindow)));
}

void TransmitterSession::Impl::onDiscoveryAnswer() {
  while (auto answer = readDiscoveryAnswer(discovery_.get())) {
    bool known = false;
    for (const auto& device : found_) known = known || device.address == answer->address;
    if (!known) found_.push_back(std::move(*answer));
  }
  std::string wanted;
  {
    std::lock_guard lock(mutex_);
    wanted = config_.device;
  }
  // The named device answered: no need to wait for the others.
  if (!wanted.empty() && pickDevice(found_, wanted)) finishDiscovery();
}

void TransmitterSession::Impl::finishDiscovery() {
  loop_.remove(discoveryWatch_);
  discoveryWatch_ = 0;
  discovery_.reset();
  std::string wanted;
  {
    std::lock_guard lock(mutex_);
    wanted = config_.device;
  }
  auto picked = pickDevice(found_, wanted);
  if (!picked) return fail(picked.error());
  startConnect(picked->address, picked->advertisement.name);
}

void TransmitterSession::Impl::startConnect(const SocketAddress& device, const std::string& name) {
  {
    std::lock_guard lock(mutex_);
    device_ = device;
    status_.vehicleAddress = device.toString();
    if (!name.empty()) status_.deviceName = name;
  }
  auto fd = startConnectTcp(device);
  if (!fd) return fail(fd.error());
  int fdNumber = fd->get();
  {
    std::lock_guard lock(sendMutex_);
    tcp_ = std::move(*fd);
  }
  // TCP's own keepalive as well, for a device that vanishes while PSD are
  // off (the link timeout normally notices first).
  int on = 1, idle = 2, interval = 1, probes = 3;
  setsockopt(fdNumber, SOL_SOCKET, SO_KEEPALIVE, &on, sizeof on);
  setsockopt(fdNumber, IPPROTO_TCP, TCP_KEEPIDLE, &idle, sizeof idle);
  setsockopt(fdNumber, IPPROTO_TCP, TCP_KEEPINTVL, &interval, sizeof interval);
  setsockopt(fdNumber, IPPROTO_TCP, TCP_KEEPCNT, &probes, sizeof probes);
  phase_ = Phase::Connecting;
  parser_ = MessageStreamParser();
  reported_ = {};
  rejectedThisConnection_ = 0;
  tcpWatch_ = loop_.watch(fdNumber, EPOLLOUT, [this](uint32_t events) { onTcp(events); });
  loop_.arm(attemptTimer_, attemptDeadline_);
}

void TransmitterSession::Impl::onTcp(uint32_t events) {
  if (phase_ == Phase::Connecting) {
    int error = pendingError(tcp_.get());
    if (error != 0 || (events & (EPOLLERR | EPOLLHUP)))
      return fail("cannot connect to " + device_->toString() + ": " +
                  errnoText(error ? error : ECONNREFUSED) +
                  " (is the device on and is that its address?)");
    return onConnected();
  }
  std::array<uint8_t, 4096> buffer;
  for (size_t taken = 0; taken < kMaxReadPerWake; taken += buffer.size()) {
    ssize_t n = ::recv(tcp_.get(), buffer.data(), buffer.size(), MSG_DONTWAIT);
    if (n == 0) return fail("the device closed the connection");
    if (n < 0) {
      if (errno == EAGAIN || errno == EWOULDBLOCK) return;
      if (errno == EINTR) continue;
      return fail("connection to the device lost: " + errnoText(errno));
    }
    bool closed = false;
    parser_.feed(std::span(buffer.data(), static_cast<size_t>(n)),
                 [&](const Expected<Message, ProtocolError>& result) {
                   // Malformed input is counted by the parser and dropped.
                   if (result && !closed) handle(*result);
                   closed = !tcp_.valid();
                 });
    if (closed) return;
    countRejected(Clock::now());
    if (!tcp_.valid()) return;
  }
}

// Malformed input is counted, summed up once a second, and past
// maxBadMessages on one connection taken as a misbehaving device.
void TransmitterSession::Impl::countRejected(Clock::time_point now) {
  const auto& stats = parser_.stats();
  // Garbage is counted in bytes: 64 of them weigh as one bad message.
  uint64_t rejected =
      stats.badCrc + stats.unknownCommands + stats.invalidMessages + stats.garbageBytes / 64;
  if (rejected == rejectedThisConnection_) return;
  rejectedUnreported_ += rejected - rejectedThisConnection_;
  uint32_t limit;
  {
    std::lock_guard lock(mutex_);
    status_.inputRejected += rejected - rejectedThisConnection_;
    limit = config_.maxBadMessages;
  }
  rejectedThisConnection_ = rejected;
  if (now - lastSummary_ >= kRejectSummaryPeriod) {
    auto since = [](uint64_t current, uint64_t before) { return std::to_string(current - before); };
    publish({link::InputRejected{
        rejectedUnreported_,
        since(stats.badCrc, reported_.badCrc) + " bad CRC, " +
            since(stats.unknownCommands, reported_.unknownCommands) + " unknown commands, " +
            since(stats.invalidMessages, reported_.invalidMessages) + " invalid, " +
            since(stats.garbageBytes, reported_.garbageBytes) + " bytes of garbage"}});
    reported_ = stats;
    rejectedUnreported_ = 0;
    lastSummary_ = now;
  }
  if (rejectedThisConnection_ > limit)
    fail("the device sent " + std::to_string(rejectedThisConnection_) +
         " malformed messages: dropped as misbehaving");
}

void TransmitterSession::Impl::onConnected() {
  loop_.setEvents(tcpWatch_, EPOLLIN);
  phase_ = Phase::LoggingIn;
  SessionConfig config;
  {
    std::lock_guard lock(mutex_);
    config = config_;
  }
  sendControl(Tl{.system = static_cast<uint8_t>(SystemType::PcClient),
                 .version = {1, 0},
                 .priority = config.priority,
                 .name = config.transmitterName,
                 .statusPort = localAddress(psdSocket_.get()).port()});
  sendControl(Ccfg{config.periods});
  sendControl(Fcfg{config.failsafe});
}

void TransmitterSession::Impl::onLoggedIn(const Wst& wst) {
  phase_ = Phase::LoggedIn;
  loop_.disarm(attemptTimer_);
  lastHeard_ = Clock::now();
  liveSince_ = lastHeard_;
  std::map<uint8_t, uint16_t> streams;
  std::string address;
  {
    std::lock_guard lock(mutex_);
    status_.state = link::LinkState::Live;
    status_.reason.clear();
    status_.connectionId = wst.connectionId;
    status_.cameraCount = wst.cameraCount;
    ++status_.logins;
    controlAddress_ = device_->withPort(wst.controlPort);
    ::connect(pcdSocket_.get(), controlAddress_->raw(), controlAddress_->size());
    streams = streamPorts_;
    address = device_->toString();
    if (config_.linkTimeout.count() > 0) loop_.arm(statusTimer_, lastHeard_ + config_.linkTimeout);
  }
  changed_.notify_all();
  publish({link::StateChanged{link::LinkState::Live, "logged in to " + address + " as connection " +
                                                         std::to_string(wst.connectionId) + " (" +
                                                         std::to_string(wst.cameraCount) +
                                                         " cameras)"}});
  for (auto [camera, port] : streams) sendControl(Stst{camera, port});
}

void TransmitterSession::Impl::handle(const Message& message) {
  if (auto* wst = std::get_if<Wst>(&message)) {
    if (phase_ == Phase::LoggingIn) onLoggedIn(*wst);
    return;
  }
  std::vector<link::LinkEvent> events;
  bool granted = false;
  {
    std::lock_guard lock(mutex_);
    if (auto* agr = std::get_if<Agr>(&message)) {
      bool had = status_.hasControl;
      bool answersRequest = controlRequests_ > 0;
      if (answersRequest) --controlRequests_;
      switch (agr->notification) {
        case AccessNotification::Granted:
          status_.hasControl = true;
          break;
        case AccessNotification::Revoked:
          status_.hasControl = false;
          break;
        case AccessNotification::Denied:
          break;
        case AccessNotification::Notification:
          status_.hasControl = agr->connectionId == status_.connectionId;
          break;
      }
      if (answersRequest) {
        bool denied = agr->notification == AccessNotification::Denied;
        events.push_back(link::ControlRequestAnswered{
            !denied, denied ? "'" + agr->name +
                                  "' holds it and only a transmitter of the highest "
                                  "priority may hand it over"
                            : ""});
      }
      if (had != status_.hasControl || agr->notification == AccessNotification::Notification)
        events.push_back(link::ControlRightChanged{status_.hasControl, agr->name});
      granted = !had && status_.hasControl;
      if (granted) pacer_.restart();
    } else if (auto* err = std::get_if<Err>(&message)) {
      ++status_.errorsReceived;
      errors_.push_back(*err);
      if (errors_.size() > 16) errors_.erase(errors_.begin());
      if (err->command == static_cast<uint8_t>(Command::Areq) && controlRequests_ > 0) {
        --controlRequests_;
        events.push_back(link::ControlRequestAnswered{false, errorCodeMeaning(err->code)});
      }
      events.push_back(
          link::DeviceRefused{commandName(err->command), err->code, errorCodeMeaning(err->code)});
    } else if (auto* tlst = std::get_if<Tlst>(&message)) {
      if (listComplete_) transmitters_.clear();
      listComplete_ = false;
      transmitters_.push_back({tlst->connectionId, tlst->priority, tlst->name});
    } else if (std::holds_alternative<Tlend>(message)) {
      listComplete_ = true;
    }
  }
  changed_.notify_all();
  if (granted) loop_.arm(pacerTimer_, Clock::now());
  publish(std::move(events));
  // The login itself refused (unauthorised, busy): no WST will come.
  if (auto* err = std::get_if<Err>(&message);
      err && phase_ == Phase::LoggingIn && err->command == static_cast<uint8_t>(Command::Tl))
    fail(std::string("the device refused the login: ") + errorCodeMeaning(err->code) + " (ERR " +
         std::to_string(err->code) + ")");
}

void TransmitterSession::Impl::closeConnection() {
  if (tcpWatch_) loop_.remove(tcpWatch_);
  tcpWatch_ = 0;
  if (discoveryWatch_) loop_.remove(discoveryWatch_);
  discoveryWatch_ = 0;
  discovery_.reset();
  std::lock_guard lock(sendMutex_);
  if (tcp_.valid()) ::shutdown(tcp_.get(), SHUT_RDWR);
  tcp_.reset();
}

void TransmitterSession::Impl::fail(const std::string& why, Retry retryWhen) {
  bool retryAtOnce = retryWhen == Retry::AtOnceForNewSettings;
  if (liveSince_ && Clock::now() - *liveSince_ >= kHealthyLink) backoff_ = kFirstBackoff;
  liveSince_.reset();
  closeConnection();
  loop_.disarm(pacerTimer_);
  loop_.disarm(statusTimer_);
  link::LinkState state;
  bool retry;
  std::vector<link::LinkEvent> events;
  {
    std::lock_guard lock(mutex_);
    ++failedAttempts_;
    if (status_.hasControl) events.push_back(link::ControlRightChanged{false, ""});
    status_.hasControl = false;
    controlAddress_.reset();
    controlRequests_ = 0;
    retry = config_.reconnect || retryAtOnce;
    state = !retry                               ? link::LinkState::Failed
            : status_.logins == 0 || retryAtOnce ? link::LinkState::Connecting
                                                 : link::LinkState::Lost;
    status_.state = state;
    status_.reason = why;
  }
  changed_.notify_all();
  milliseconds wait = retryAtOnce ? milliseconds(0) : backoff_;
  std::string reason = why;
  if (retry && !retryAtOnce) reason += "; retrying in " + std::to_string(wait.count()) + " ms";
  events.insert(events.begin(), link::StateChanged{state, reason});
  publish(std::move(events));
  if (!retry) {
    phase_ = Phase::Closed;
    return;
  }
  phase_ = Phase::Waiting;
  if (!retryAtOnce) backoff_ = std::min(backoff_ * 2, kMaxBackoff);
  loop_.arm(attemptTimer_, Clock::now() + wait);
}

void TransmitterSession::Impl::onPsd() {
  std::array<uint8_t, 64> buffer;
  sockaddr_in from{};
  socklen_t size = sizeof from;
  ssize_t n;
  // At most a few per wake-up: a flood on this port cannot starve the loop.
  for (int taken = 0;
       taken < 16 && (n = ::recvfrom(psdSocket_.get(), buffer.data(), buffer.size(), MSG_DONTWAIT,
                                     reinterpret_cast<sockaddr*>(&from), &size)) >= 0;
       ++taken) {
    auto message = decode(std::span(buffer.data(), static_cast<size_t>(n)));
    if (!message || !std::holds_alternative<Psd>(*message)) continue;
    const auto& psd = std::get<Psd>(*message);
    link::Telemetry telemetry{
        .batteryVolts = psd.batteryMillivolts / 1000.0,
        .analogVolts = psd.analogMillivolts / 1000.0,
        .inputs = static_cast<uint32_t>(psd.inputs[0] | psd.inputs[1] << 1 | psd.inputs[2] << 2 |
                                        psd.inputs[3] << 3),
        .received = Clock::now()};
    {
      std::lock_guard lock(mutex_);
      if (!device_ || !device_->sameHost(SocketAddress(from))) continue;  // not our device
      lastHeard_ = telemetry.received;
      status_.lastStatus = psd;
      status_.telemetry = telemetry;
    }
    publish({link::TelemetryReceived{telemetry}});
  }
}

void TransmitterSession::Impl::onStatusTimer() {
  if (phase_ != Phase::LoggedIn) return;
  milliseconds timeout;
  {
    std::lock_guard lock(mutex_);
    timeout = config_.linkTimeout;
  }
  auto silent = Clock::now() - lastHeard_;
  if (timeout.count() > 0 && silent >= timeout)
    return fail("no status report from the device for " +
                std::to_string(std::chrono::duration_cast<milliseconds>(silent).count()) +
                " ms (link-timeout): it is off, out of range or gone");
  loop_.arm(statusTimer_, lastHeard_ + timeout);
}

void TransmitterSession::Impl::onPacerTimer() {
  auto now = Clock::now();
  std::optional<link::Pulses> due;
  Clock::time_point next;
  {
    std::lock_guard lock(mutex_);
    if (status_.state != link::LinkState::Live || !status_.hasControl || !controlAddress_) return;
    due = pacer_.poll(now);
    next = pacer_.nextDeadline(now);
  }
  if (due) sendPcd(*due);
  // Not arm(): a command set while this ran may have armed an earlier wake
  // (computed after `next`), which must not be pushed back.
  loop_.armIfEarlier(pacerTimer_, next);
}

// ---------------------------------------------------------------------------

Expected<std::shared_ptr<TransmitterSession>, std::string> TransmitterSession::acquire(
    const SessionConfig& config, const std::string& user) {
  if (config.keepalive > kMaxKeepalive || config.keepalive.count() <= 0)
    return unexpected("keepalive " + ms(config.keepalive) + " is outside 1.." + ms(kMaxKeepalive) +
                      ": it must stay well below the device's PCD timeout (200..2000 ms)");
  if (config.linkTimeout.count() > 0 && config.linkTimeout < milliseconds(2 * kPsdPeriodMs))
    return unexpected("link-timeout " + ms(config.linkTimeout) + " is shorter than two status " +
                      "reports (" + ms(milliseconds(2 * kPsdPeriodMs)) + "): use 0 (off) or more");
  if (auto tl = encode(Tl{.name = config.transmitterName}); !tl)
    return unexpected("transmitter-name " + quoted(config.transmitterName) +
                      " cannot be sent: " + tl.error().message());

  std::shared_ptr<TransmitterSession> session;
  {
    static std::mutex registryMutex;
    static std::map<std::string, std::weak_ptr<TransmitterSession>> registry;
    std::lock_guard lock(registryMutex);
    auto& entry = registry[config.key()];
    session = entry.lock();
    if (!session) {
      session.reset(new TransmitterSession(config));
      entry = session;
    }
  }

  // Take over the settings `user` gave, unless someone else gave others.
  auto* impl = session->impl_.get();
  bool relogin = false;
  {
    std::lock_guard settingsLock(impl->mutex_);
    for (const auto& setting : sharedSettings()) {
      if (!config.given.count(setting.name)) continue;
      std::string wanted = setting.text(config), current = setting.text(impl->config_);
      auto owner = impl->owners_.find(setting.name);
      if (wanted != current && owner != impl->owners_.end() && owner->second != user)
        return unexpected(std::string(setting.name) + "=" + wanted + " of " + user +
                          " conflicts with " + setting.name + "=" + current + " of " +
                          owner->second + ", which shares the link to " + config.key() +
                          ": give both the same value, or set it on one only");
      impl->owners_[setting.name] = user;
      if (wanted == current) continue;
      setting.adopt(impl->config_, config);
      relogin = relogin || setting.needsLogin;
    }
    impl->pacer_ = link::CommandPacer(pacerConfig(impl->config_));
  }
  if (relogin) {
    impl->loop_.invoke([impl, &user] {
      if (impl->phase_ == Impl::Phase::LoggingIn || impl->phase_ == Impl::Phase::LoggedIn)
        impl->fail("logging in again with the settings of " + user,
                   Impl::Retry::AtOnceForNewSettings);
    });
  }

  // Each user holds its own reference; dropping it gives its settings back.
  auto* strong = new std::shared_ptr<TransmitterSession>(session);
  return std::shared_ptr<TransmitterSession>(session.get(),
                                             [strong, user](TransmitterSession* link) {
                                               link->release(user);
                                               delete strong;
                                             });
}

TransmitterSession::TransmitterSession(const SessionConfig& config)
    : impl_(std::make_unique<Impl>(config, listeners_)) {}

TransmitterSession::~TransmitterSession() = default;

void TransmitterSession::release(const std::string& user) {
  std::lock_guard lock(impl_->mutex_);
  std::erase_if(impl_->owners_, [&](const auto& owner) { return owner.second == user; });
}

std::optional<std::string> TransmitterSession::waitLoggedIn(milliseconds timeout) {
  std::unique_lock lock(impl_->mutex_);
  bool done = impl_->changed_.wait_for(lock, timeout, [&] {
    return impl_->status_.state == link::LinkState::Live || impl_->failedAttempts_ > 0;
  });
  if (impl_->status_.state == link::LinkState::Live) return std::nullopt;
  if (!done) return "no login within " + std::to_string(timeout.count()) + " ms";
  return impl_->status_.reason;
}

link::LinkStatus TransmitterSession::status() const { return sessionStatus(); }

SessionStatus TransmitterSession::sessionStatus() const {
  std::lock_guard lock(impl_->mutex_);
  return impl_->status_;
}

std::optional<SocketAddress> TransmitterSession::deviceAddress() const {
  std::lock_guard lock(impl_->mutex_);
  return impl_->device_;
}

void TransmitterSession::startStream(uint8_t camera, uint16_t port) {
  bool live;
  {
    std::lock_guard lock(impl_->mutex_);
    impl_->streamPorts_[camera] = port;
    live = impl_->status_.state == link::LinkState::Live;
  }
  // Not live yet: the login sends it.
  if (live) impl_->sendControl(Stst{camera, port});
}

void TransmitterSession::stopStream(uint8_t camera) {
  {
    std::lock_guard lock(impl_->mutex_);
    impl_->streamPorts_.erase(camera);
  }
  impl_->sendControl(Est{camera});
}

void TransmitterSession::setCommand(const link::Pulses& pulses) {
  auto now = Clock::now();
  std::optional<link::Pulses> due;
  Clock::time_point next;
  bool steering;
  {
    std::lock_guard lock(impl_->mutex_);
    due = impl_->pacer_.offer(pulses, now);
    steering = impl_->status_.state == link::LinkState::Live && impl_->status_.hasControl &&
               impl_->controlAddress_;
    next = impl_->pacer_.nextDeadline(now);
  }
  if (!steering) return;  // kept for when the control right comes
  // A change leaves now, from this thread: no wait for a tick.
  if (due) impl_->sendPcd(*due);
  impl_->loop_.armIfEarlier(impl_->pacerTimer_, next);
}

void TransmitterSession::requestControl() {
  uint8_t id;
  {
    std::lock_guard lock(impl_->mutex_);
    id = impl_->status_.connectionId;
  }
  requestControlFor(id);
}

void TransmitterSession::requestControlFor(uint8_t connectionId) {
  {
    std::lock_guard lock(impl_->mutex_);
    ++impl_->controlRequests_;
  }
  if (!impl_->sendControl(Areq{connectionId})) {
    {
      std::lock_guard lock(impl_->mutex_);
      --impl_->controlRequests_;
    }
    impl_->publish({link::ControlRequestAnswered{false, "not logged in"}});
  }
}

std::optional<std::vector<TransmitterInfo>> TransmitterSession::listTransmitters(
    milliseconds timeout) {
  {
    std::lock_guard lock(impl_->mutex_);
    impl_->listComplete_ = false;
    impl_->transmitters_.clear();
  }
  if (!impl_->sendControl(Tlr{})) return std::nullopt;
  std::unique_lock lock(impl_->mutex_);
  if (!impl_->changed_.wait_for(lock, timeout, [&] { return impl_->listComplete_; }))
    return std::nullopt;
  return impl_->transmitters_;
}

std::optional<Err> TransmitterSession::sendConfiguration(const Message& message,
                                                         milliseconds timeout) {
  uint8_t command = commandCode(message);
  {
    std::lock_guard lock(impl_->mutex_);
    impl_->errors_.clear();
  }
  if (!impl_->sendControl(message)) return Err{command, static_cast<uint16_t>(ErrorCode::System)};
  std::unique_lock lock(impl_->mutex_);
  std::optional<Err> answer;
  impl_->changed_.wait_for(lock, timeout, [&] {
    for (const auto& err : impl_->errors_)
      if (err.command == command) answer = err;
    return answer.has_value();
  });
  return answer;
}

}  // namespace wircam::wirc
