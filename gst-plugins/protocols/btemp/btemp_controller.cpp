#include "btemp/btemp_controller.h"

#include <sys/epoll.h>
#include <sys/socket.h>

#include <algorithm>
#include <array>
#include <mutex>
#include <random>

#include "btemp/btemp_probe.h"
#include "common/priority_inheriting_mutex.h"
#include "common/socket.h"
#include "link/alarm.h"
#include "link/command_pacer.h"
#include "link/event_loop.h"
#include "link/link_registry.h"

namespace wircam::btemp {

using link::Clock;
using link::EventLoop;
using std::chrono::milliseconds;

namespace {

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

link::SettingValues ControllerConfig::settings() const {
  return {{"ctrl-period", ms(ctrlPeriod)},
          {"keepalive-timeout", ms(keepaliveTimeout)},
          {"lost-timeout", ms(commandTtl)},
          {"rate", std::to_string(static_cast<int>(rateLimit))},
          {"map", map.toString()}};
}

// The I/O around the Registration: the socket and timers on the event loop.
class Controller::Impl {
 public:
  Impl(ControllerConfig config, UniqueFd socket, link::LinkListeners& listeners, EventLoop& loop);
  ~Impl();

  void onReadable();
  void onPhaseTimer();
  void onPacerAlarm();
  void perform(RegistrationActions actions);
  void armPhaseTimer();
  void send(const Message& message, const SocketAddress& to) {
    if (sendDatagram(socket_.get(), to, encode(message))) {
      MutexLock lock(mutex_);
      registration_.countCommandSent();
    }
  }
  Ctrl ctrlOf(const link::Pulses& pulses) const {
    Ctrl ctrl;
    for (size_t channel = 1; channel <= ctrl.throttle.size(); ++channel)
      ctrl.throttle[channel - 1] = config_.map.toByte(channel, pulses[channel - 1]);
    return ctrl;
  }

  EventLoop& loop_;
  const ControllerConfig config_;
  const NodeInfo self_{randomGuid(), nodeFlags(NodeType::Controller)};
  UniqueFd socket_;
  link::LinkListeners& listeners_;
  EventLoop::Id watch_ = 0, phaseTimer_ = 0;
  link::Alarm pacerAlarm_;

  // Guards what follows; never held while sending or emitting. Shared by
  // the loop with the streams' threads, so it lends priority (event_loop.h).
  mutable PriorityInheritingMutex mutex_;
  Registration registration_;
  link::CommandPacer pacer_;
};

Controller::Impl::Impl(ControllerConfig config, UniqueFd socket, link::LinkListeners& listeners,
                       EventLoop& loop)
    : loop_(loop),
      config_(std::move(config)),
      socket_(std::move(socket)),
      listeners_(listeners),
      pacerAlarm_(loop, [this] { onPacerAlarm(); }),
      registration_(self_, config_.host, config_.port, config_.keepaliveTimeout, Clock::now()),
      pacer_({.keepalive = config_.ctrlPeriod,
              .minInterval = link::intervalOf(config_.rateLimit),
              .ttl = config_.commandTtl,
              .failsafe = config_.failsafe,
              .keepaliveEarly = EventLoop::kCoalesce}) {
  watch_ = loop_.watch(socket_.get(), EPOLLIN, [this](uint32_t) { onReadable(); });
  phaseTimer_ = loop_.addTimer([this] { onPhaseTimer(); });
  loop_.arm(phaseTimer_, Clock::now());
}

Controller::Impl::~Impl() {
  loop_.invoke([this] {
    for (auto id : {watch_, phaseTimer_}) loop_.remove(id);
    pacerAlarm_.stop();
  });
  // The last word is the failsafe, so the robot stops now.
  std::optional<SocketAddress> robot;
  {
    MutexLock lock(mutex_);
    robot = registration_.registeredRobot();
  }
  if (robot) send(ctrlOf(config_.failsafe), *robot);
}

void Controller::Impl::perform(RegistrationActions actions) {
  for (auto& action : actions) {
    if (auto* probe = std::get_if<registration::Probe>(&action)) {
      sendProbes(socket_.get(), probe->host, probe->port, config_.broadcastAddress, Ping{self_});
    } else if (auto* message = std::get_if<registration::Send>(&action)) {
      send(message->message, message->to);
    } else if (auto* emit = std::get_if<registration::Emit>(&action)) {
      listeners_.emit(emit->event);
    } else if (std::holds_alternative<registration::StartCommands>(action)) {
      MutexLock lock(mutex_);
      pacer_.restart();
      pacerAlarm_.set(Clock::now());
    }
  }
}

void Controller::Impl::armPhaseTimer() {
  Clock::time_point deadline;
  {
    MutexLock lock(mutex_);
    deadline = registration_.nextDeadline();
  }
  loop_.arm(phaseTimer_, deadline);
}

void Controller::Impl::onPhaseTimer() {
  RegistrationActions actions;
  {
    MutexLock lock(mutex_);
    actions = registration_.onDeadline(Clock::now());
  }
  armPhaseTimer();
  perform(std::move(actions));
}

void Controller::Impl::onPacerAlarm() {
  auto now = Clock::now();
  std::optional<link::Pulses> due;
  std::optional<SocketAddress> robot;
  bool commanded;
  {
    MutexLock lock(mutex_);
    robot = registration_.registeredRobot();
    if (!robot) return;
    commanded = pacer_.commanded();
    if (commanded) {
      due = pacer_.poll(now);
      pacerAlarm_.set(pacer_.nextWindow(now));
    } else {
      pacerAlarm_.set(now + kIdlePeriod);
    }
  }
  // Nothing worthwhile to send: IDLE tells the robot we are still here.
  if (!commanded) return send(Idle{}, *robot);
  if (due) send(ctrlOf(*due), *robot);
}

void Controller::Impl::onReadable() {
  std::array<uint8_t, 2048> buffer;
  RegistrationActions actions;
  receiveDatagrams(socket_.get(), buffer, 64, [&](auto datagram, const SocketAddress& from) {
    MutexLock lock(mutex_);
    auto caused = registration_.onDatagram(from, datagram, Clock::now());
    actions.insert(actions.end(), caused.begin(), caused.end());
  });
  {
    MutexLock lock(mutex_);
    if (auto summary = registration_.rejectSummary(Clock::now()))
      actions.push_back(registration::Emit{*summary});
  }
  armPhaseTimer();
  perform(std::move(actions));
}

Expected<std::shared_ptr<Controller>, std::string> Controller::acquire(
    const ControllerConfig& config, const std::string& user, EventLoop& loop) {
  if (config.ctrlPeriod.count() <= 0 || config.ctrlPeriod >= config.keepaliveTimeout)
    return unexpected("ctrl period " + ms(config.ctrlPeriod) +
                      " must be above 0 and below the keepalive timeout (" +
                      ms(config.keepaliveTimeout) + ")");
  static link::LinkRegistry<Controller> registry;
  return registry.acquire(
      loop, config.key(), config.settings(), user,
      [&]() -> Expected<std::shared_ptr<Controller>, std::string> {
        if (!config.host.empty())
          if (auto robot = SocketAddress::resolve(config.host, config.port); !robot)
            return unexpected(robot.error());
        auto socket = openBroadcastSocket();
        if (!socket) return unexpected(socket.error());
        std::shared_ptr<Controller> link(new Controller());
        link->impl_ = std::make_unique<Impl>(config, std::move(*socket), link->listeners_, loop);
        return link;
      });
}

Controller::~Controller() = default;

void Controller::setCommand(const link::Pulses& pulses) {
  auto now = Clock::now();
  std::optional<link::Pulses> due;
  std::optional<SocketAddress> robot;
  {
    MutexLock lock(impl_->mutex_);
    due = impl_->pacer_.offer(pulses, now);
    robot = impl_->registration_.registeredRobot();
    if (!robot) return;  // kept for when the robot is registered
    impl_->pacerAlarm_.set(impl_->pacer_.nextWindow(now));
  }
  if (due) impl_->send(impl_->ctrlOf(*due), *robot);
}

void Controller::requestControl() {
  bool registered = controllerStatus().hasControl;
  impl_->listeners_.emit(link::ControlRequestAnswered{
      registered, registered ? "" : "not registered with the robot yet (RCTR unanswered)"});
}

ControllerStatus Controller::controllerStatus() const {
  MutexLock lock(impl_->mutex_);
  return impl_->registration_.status();
}

}  // namespace wircam::btemp
