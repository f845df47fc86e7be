#include "btemp/btemp_controller.h"

#include <sys/epoll.h>
#include <sys/socket.h>

#include <algorithm>
#include <array>
#include <mutex>
#include <random>

#include "btemp/btemp_probe.h"
#include "common/socket.h"
#include "link/command_pacer.h"
#include "link/event_loop.h"
#include "link/link_registry.h"
#include "link/reject_tally.h"

namespace wircam::btemp {

using link::Clock;
using link::EventLoop;
using std::chrono::milliseconds;

namespace {

constexpr milliseconds kProbePeriod{1000};
constexpr milliseconds kIdlePeriod{1000};

std::string ms(milliseconds value) { return std::to_string(value.count()) + "ms"; }

}  // namespace

Guid randomGuid() {
  std::random_device random;
  Guid guid;
  for (auto& byte : guid) byte = static_cast<uint8_t>(random());
  return guid;
}

std::string ControllerConfig::key() const {
  return host.empty() ? "btemp://broadcast:" + std::to_string(port)
                      : "btemp://" + host + ":" + std::to_string(port);
}

std::string ControllerConfig::settings() const {
  std::string text =
      "ctrl-period=" + ms(ctrlPeriod) + " keepalive-timeout=" + ms(keepaliveTimeout) +
      " lost-timeout=" + ms(commandTtl) + " rate=" + std::to_string(static_cast<int>(rateLimit));
  if (auto overrides = map.toString(); !overrides.empty()) text += " map=" + overrides;
  return text;
}

class Controller::Impl {
 public:
  enum class Phase { Probing, Registering, Registered };

  Impl(ControllerConfig config, UniqueFd socket, link::LinkListeners& listeners);
  ~Impl();

  void onReadable();
  void handle(const Message& message, const SocketAddress& from, Clock::time_point now,
              std::vector<link::LinkEvent>& events);
  void onPhaseTimer();
  void onPacerTimer();
  void send(const Message& message, const SocketAddress& to) {
    if (sendDatagram(socket_.get(), to, encode(message))) {
      std::lock_guard lock(mutex_);
      ++status_.commandsSent;
    }
  }
  Ctrl ctrlOf(const link::Pulses& pulses) const {
    Ctrl ctrl;
    for (size_t channel = 1; channel <= ctrl.throttle.size(); ++channel)
      ctrl.throttle[channel - 1] = config_.map.toByte(channel, pulses[channel - 1]);
    return ctrl;
  }
  void publish(const std::vector<link::LinkEvent>& events) {
    for (const auto& event : events) listeners_.emit(event);
  }

  const ControllerConfig config_;
  const NodeInfo self_{randomGuid(), nodeFlags(NodeType::Controller)};
  // The host named in the settings, resolved once (unset: broadcast probing).
  std::optional<SocketAddress> namedHost_;
  UniqueFd socket_;
  link::LinkListeners& listeners_;
  EventLoop& loop_ = EventLoop::shared();
  EventLoop::Id watch_ = 0, phaseTimer_ = 0, pacerTimer_ = 0;

  // Loop thread only.
  link::RejectTally rejected_;
  Clock::time_point lastHeard_{};

  // Guards what follows; never held while sending or emitting.
  mutable std::mutex mutex_;
  Phase phase_ = Phase::Probing;
  std::optional<SocketAddress> robot_;
  link::CommandPacer pacer_;
  ControllerStatus status_;
};

Controller::Impl::Impl(ControllerConfig config, UniqueFd socket, link::LinkListeners& listeners)
    : config_(std::move(config)),
      socket_(std::move(socket)),
      listeners_(listeners),
      pacer_({.keepalive = config_.ctrlPeriod,
              .minInterval = link::intervalOf(config_.rateLimit),
              .ttl = config_.commandTtl,
              .failsafe = config_.failsafe,
              .keepaliveEarly = EventLoop::kCoalesce}) {
  status_.reason = "looking for the robot";
  if (!config_.host.empty())
    if (auto host = SocketAddress::resolve(config_.host, config_.port)) namedHost_ = *host;
  watch_ = loop_.watch(socket_.get(), EPOLLIN, [this](uint32_t) { onReadable(); });
  phaseTimer_ = loop_.addTimer([this] { onPhaseTimer(); });
  pacerTimer_ = loop_.addTimer([this] { onPacerTimer(); });
  loop_.arm(phaseTimer_, Clock::now());
}

Controller::Impl::~Impl() {
  loop_.invoke([this] {
    for (auto id : {watch_, phaseTimer_, pacerTimer_}) loop_.remove(id);
  });
  // The last word is the failsafe, so the robot stops now.
  std::optional<SocketAddress> robot;
  {
    std::lock_guard lock(mutex_);
    if (phase_ == Phase::Registered) robot = robot_;
  }
  if (robot) send(ctrlOf(config_.failsafe), *robot);
}

// Probing and registering repeat every second; once registered this timer
// watches the robot's silence.
void Controller::Impl::onPhaseTimer() {
  auto now = Clock::now();
  Phase phase;
  std::optional<SocketAddress> robot;
  {
    std::lock_guard lock(mutex_);
    phase = phase_;
    robot = robot_;
  }
  switch (phase) {
    case Phase::Probing: {
      // After a loss the robot is looked for where it was.
      std::string host = robot ? robot->host() : config_.host;
      uint16_t port = robot ? robot->port() : config_.port;
      sendProbes(socket_.get(), host, port, config_.broadcastAddress, Ping{self_});
      return loop_.arm(phaseTimer_, now + kProbePeriod);
    }
    case Phase::Registering:
      send(Rctr{.node = self_.node}, *robot);
      return loop_.arm(phaseTimer_, now + kProbePeriod);
    case Phase::Registered:
      break;
  }
  auto silent = now - lastHeard_;
  if (silent < config_.keepaliveTimeout)
    return loop_.arm(phaseTimer_, lastHeard_ + config_.keepaliveTimeout);
  std::string reason = "nothing from the robot at " + robot->toString() + " for " +
                       std::to_string(std::chrono::duration_cast<milliseconds>(silent).count()) +
                       " ms (keepalive timeout): looking for it again";
  {
    std::lock_guard lock(mutex_);
    phase_ = Phase::Probing;
    status_.state = link::LinkState::Lost;
    status_.reason = reason;
    status_.hasControl = false;
  }
  loop_.disarm(pacerTimer_);
  publish(
      {link::StateChanged{link::LinkState::Lost, reason}, link::ControlRightChanged{false, ""}});
  loop_.arm(phaseTimer_, now);
}

void Controller::Impl::onPacerTimer() {
  auto now = Clock::now();
  std::optional<link::Pulses> due;
  Clock::time_point next;
  std::optional<SocketAddress> robot;
  bool commanded;
  {
    std::lock_guard lock(mutex_);
    if (phase_ != Phase::Registered) return;
    robot = robot_;
    commanded = pacer_.commanded();
    if (commanded) {
      due = pacer_.poll(now);
      next = pacer_.nextDeadline(now);
    }
  }
  if (!commanded) {
    // Nothing worthwhile to send: IDLE tells the robot we are still here.
    send(Idle{}, *robot);
    return loop_.armIfEarlier(pacerTimer_, now + kIdlePeriod);
  }
  if (due) send(ctrlOf(*due), *robot);
  // Not arm(): a command set while this ran may have armed an earlier wake
  // (computed after `next`), which must not be pushed back.
  loop_.armIfEarlier(pacerTimer_, next);
}

void Controller::Impl::onReadable() {
  std::array<uint8_t, 2048> buffer;
  std::vector<link::LinkEvent> events;
  receiveDatagrams(socket_.get(), buffer, 64, [&](auto datagram, const SocketAddress& from) {
    {
      std::lock_guard lock(mutex_);
      // Until a robot answers, only answers from the named host count.
      bool foreign = robot_ ? !(from == *robot_) : namedHost_ && !from.sameHost(*namedHost_);
      if (foreign) {
        ++status_.foreignDatagrams;
        return;
      }
    }
    auto message = decode(datagram);
    if (!message) {
      rejected_.count(decodeErrorName(message.error()));
      std::lock_guard lock(mutex_);
      status_.inputRejected = rejected_.total();
      return;
    }
    handle(*message, from, Clock::now(), events);
  });
  if (auto summary = rejected_.summary(Clock::now())) events.push_back(*summary);
  publish(events);
}

void Controller::Impl::handle(const Message& message, const SocketAddress& from,
                              Clock::time_point now, std::vector<link::LinkEvent>& events) {
  std::unique_lock lock(mutex_);
  if (robot_ && from == *robot_) lastHeard_ = now;
  if (const auto* piak = std::get_if<Piak>(&message)) {
    if (phase_ != Phase::Probing || nodeTypeOf(piak->node.flags) != NodeType::Robot) return;
    robot_ = from;
    status_.robot = piak->node;
    status_.vehicleAddress = from.toString();
    phase_ = Phase::Registering;
    lastHeard_ = now;
    lock.unlock();
    loop_.arm(phaseTimer_, now);  // RCTR at once
  } else if (std::holds_alternative<Rcak>(message)) {
    if (phase_ != Phase::Registering) return;
    bool again = status_.logins > 0;
    phase_ = Phase::Registered;
    status_.state = link::LinkState::Live;
    status_.reason.clear();
    status_.hasControl = true;
    ++status_.logins;
    pacer_.restart();
    std::string robot = status_.vehicleAddress + " (" + formatGuid(status_.robot->node) + ")";
    lock.unlock();
    events.push_back(link::StateChanged{
        link::LinkState::Live,
        (again ? "registered again with robot " : "registered with robot ") + robot});
    events.push_back(link::ControlRightChanged{true, ""});
    loop_.arm(pacerTimer_, now);
    loop_.arm(phaseTimer_, now + config_.keepaliveTimeout);
  } else if (const auto* pins = std::get_if<Pins>(&message)) {
    link::Telemetry telemetry{.inputs = pins->inputs, .outputs = pins->outputs, .received = now};
    size_t next = 0;
    for (int pin = 0; pin < 32; ++pin)
      if (pins->pdmMask >> pin & 1) telemetry.pdmDuty[pin] = pins->duty[next++];
    status_.lastPins = *pins;
    status_.telemetry = telemetry;
    lock.unlock();
    events.push_back(link::TelemetryReceived{telemetry});
  } else if (const auto* ping = std::get_if<Ping>(&message)) {
    bool answer = !ping->sender || wantsResponse(ping->sender->flags);
    lock.unlock();
    if (answer) send(Piak{self_}, from);
  } else if (std::holds_alternative<VideoSegment>(message)) {
    ++status_.videoSegments;
  }
  // IDLE only shows the robot is alive (lastHeard_); RCTR and CTRL are a
  // controller's, not a robot's, to send: ignored.
}

Expected<std::shared_ptr<Controller>, std::string> Controller::acquire(
    const ControllerConfig& config) {
  if (config.ctrlPeriod.count() <= 0 || config.ctrlPeriod >= config.keepaliveTimeout)
    return unexpected("ctrl period " + ms(config.ctrlPeriod) +
                      " must be above 0 and below the keepalive timeout (" +
                      ms(config.keepaliveTimeout) + ")");
  static link::LinkRegistry<Controller> registry;
  return registry.acquire(
      config.key(), config.settings(), [&]() -> Expected<std::shared_ptr<Controller>, std::string> {
        if (!config.host.empty())
          if (auto robot = SocketAddress::resolve(config.host, config.port); !robot)
            return unexpected(robot.error());
        auto socket = openBroadcastSocket();
        if (!socket) return unexpected(socket.error());
        std::shared_ptr<Controller> link(new Controller());
        link->impl_ = std::make_unique<Impl>(config, std::move(*socket), link->listeners_);
        return link;
      });
}

Controller::~Controller() = default;

void Controller::setCommand(const link::Pulses& pulses) {
  auto now = Clock::now();
  std::optional<link::Pulses> due;
  std::optional<SocketAddress> robot;
  Clock::time_point next;
  {
    std::lock_guard lock(impl_->mutex_);
    due = impl_->pacer_.offer(pulses, now);
    next = impl_->pacer_.nextDeadline(now);
    if (impl_->phase_ == Impl::Phase::Registered) robot = impl_->robot_;
  }
  if (!robot) return;  // kept for when the robot is registered
  if (due) impl_->send(impl_->ctrlOf(*due), *robot);
  impl_->loop_.armIfEarlier(impl_->pacerTimer_, next);
}

void Controller::requestControl() {
  bool registered = controllerStatus().hasControl;
  impl_->publish({link::ControlRequestAnswered{
      registered, registered ? "" : "not registered with the robot yet (RCTR unanswered)"}});
}

ControllerStatus Controller::controllerStatus() const {
  std::lock_guard lock(impl_->mutex_);
  return impl_->status_;
}

}  // namespace wircam::btemp
