#include "rcoip/rcoip_transmitter.h"

#include <sys/epoll.h>
#include <sys/socket.h>

#include <algorithm>
#include <array>
#include <mutex>

#include "common/priority_inheriting_mutex.h"
#include "common/socket.h"
#include "link/alarm.h"
#include "link/command_pacer.h"
#include "link/event_loop.h"
#include "link/link_registry.h"

namespace wircam::rcoip {

using link::Clock;
using link::EventLoop;
using std::chrono::milliseconds;

namespace {

std::string ms(milliseconds value) { return std::to_string(value.count()) + "ms"; }

Expected<std::monostate, std::string> validate(const TransmitterConfig& c) {
  if (c.channelCount < 1 || c.channelCount > link::kChannels)
    return unexpected("channels=" + std::to_string(c.channelCount) + ": RCOIP carries 1.." +
                      std::to_string(link::kChannels) + " of the vehicle's channels here");
  if (c.failInterval <= milliseconds(kReplyIntervalMs))
    return unexpected("fail interval " + ms(c.failInterval) +
                      " must be longer than the receiver's reply interval (1000ms)");
  if (c.keepalive.count() <= 0 || c.keepalive >= c.failInterval)
    return unexpected("keepalive " + ms(c.keepalive) +
                      " must be above 0 and below the fail interval (" + ms(c.failInterval) +
                      "), or the receiver fails safe between two commands");
  return std::monostate{};
}

}  // namespace

link::SettingValues TransmitterConfig::settings() const {
  return {{"channels", std::to_string(channelCount)},
          {"keepalive", ms(keepalive)},
          {"fail-interval", ms(failInterval)},
          {"lost-timeout", ms(commandTtl)},
          {"rate", std::to_string(static_cast<int>(rateLimit))},
          {"map", map.toString()}};
}

class Transmitter::Impl {
 public:
  Impl(TransmitterConfig config, SocketAddress receiver, UniqueFd socket,
       link::LinkListeners& listeners, EventLoop& loop);
  ~Impl();

  void onReadable();
  void onPacerAlarm();
  void onSilenceTimer();
  void armSilenceTimer();
  void send(const link::Pulses& pulses);
  void publish(const std::vector<link::LinkEvent>& events) {
    for (const auto& event : events) listeners_.emit(event);
  }

  EventLoop& loop_;
  const TransmitterConfig config_;
  const SocketAddress receiver_;
  UniqueFd socket_;
  link::LinkListeners& listeners_;
  EventLoop::Id watch_ = 0, silenceTimer_ = 0;
  link::Alarm pacerAlarm_;

  // Guards what follows; never held while sending or emitting. Shared by
  // the loop with the streams' threads, so it lends priority (event_loop.h).
  mutable PriorityInheritingMutex mutex_;
  link::CommandPacer pacer_;
  ReplyMonitor monitor_;
};

Transmitter::Impl::Impl(TransmitterConfig config, SocketAddress receiver, UniqueFd socket,
                        link::LinkListeners& listeners, EventLoop& loop)
    : loop_(loop),
      config_(std::move(config)),
      receiver_(receiver),
      socket_(std::move(socket)),
      listeners_(listeners),
      pacerAlarm_(loop, [this] { onPacerAlarm(); }),
      pacer_({.keepalive = config_.keepalive,
              .minInterval = link::intervalOf(config_.rateLimit),
              .ttl = config_.commandTtl,
              .failsafe = config_.failsafe,
              .keepaliveEarly = EventLoop::kCoalesce}),
      monitor_(receiver_, config_.failInterval) {
  watch_ = loop_.watch(socket_.get(), EPOLLIN, [this](uint32_t) { onReadable(); });
  silenceTimer_ = loop_.addTimer([this] { onSilenceTimer(); });
  pacerAlarm_.set(Clock::now());
}

Transmitter::Impl::~Impl() {
  loop_.invoke([this] {
    for (auto id : {watch_, silenceTimer_}) loop_.remove(id);
    pacerAlarm_.stop();
  });
  // The last word is the failsafe, so the vehicle stops now rather than
  // after its fail interval.
  send(config_.failsafe);
}

void Transmitter::Impl::send(const link::Pulses& pulses) {
  Command command;
  for (size_t channel = 1; channel <= config_.channelCount; ++channel)
    command.channels.push_back(config_.map.toByte(channel, pulses[channel - 1]));
  if (sendDatagram(socket_.get(), receiver_, encode(command))) {
    MutexLock lock(mutex_);
    monitor_.countCommandSent();
  }
}

void Transmitter::Impl::onPacerAlarm() {
  auto now = Clock::now();
  std::optional<link::Pulses> due;
  {
    MutexLock lock(mutex_);
    due = pacer_.poll(now);
    pacerAlarm_.set(pacer_.nextWindow(now));
  }
  if (due) send(*due);
}

void Transmitter::Impl::onReadable() {
  std::array<uint8_t, 512> buffer;
  std::vector<link::LinkEvent> events;
  receiveDatagrams(socket_.get(), buffer, 64, [&](auto datagram, const SocketAddress& from) {
    MutexLock lock(mutex_);
    auto caused = monitor_.onDatagram(from, datagram, Clock::now());
    events.insert(events.end(), caused.begin(), caused.end());
  });
  {
    MutexLock lock(mutex_);
    if (auto summary = monitor_.rejectSummary(Clock::now())) events.push_back(*summary);
  }
  armSilenceTimer();
  publish(events);
}

void Transmitter::Impl::onSilenceTimer() {
  std::vector<link::LinkEvent> events;
  {
    MutexLock lock(mutex_);
    events = monitor_.onDeadline(Clock::now());
  }
  armSilenceTimer();
  publish(events);
}

void Transmitter::Impl::armSilenceTimer() {
  std::optional<Clock::time_point> deadline;
  {
    MutexLock lock(mutex_);
    deadline = monitor_.nextDeadline();
  }
  if (deadline)
    loop_.arm(silenceTimer_, *deadline);
  else
    loop_.disarm(silenceTimer_);
}

Expected<std::shared_ptr<Transmitter>, std::string> Transmitter::acquire(
    const TransmitterConfig& config, const std::string& user, EventLoop& loop) {
  if (auto valid = validate(config); !valid) return unexpected(valid.error());
  static link::LinkRegistry<Transmitter> registry;
  return registry.acquire(loop, config.key(), config.settings(), user,
                          [&]() -> Expected<std::shared_ptr<Transmitter>, std::string> {
                            auto receiver = SocketAddress::resolve(config.host, config.port);
                            if (!receiver) return unexpected(receiver.error());
                            auto socket = bindUdp(*SocketAddress::resolve("", 0));
                            if (!socket) return unexpected(socket.error());
                            setNonBlocking(socket->get());
                            std::shared_ptr<Transmitter> link(new Transmitter());
                            link->impl_ = std::make_unique<Impl>(
                                config, *receiver, std::move(*socket), link->listeners_, loop);
                            return link;
                          });
}

Transmitter::~Transmitter() = default;

void Transmitter::setCommand(const link::Pulses& pulses) {
  auto now = Clock::now();
  std::optional<link::Pulses> due;
  {
    MutexLock lock(impl_->mutex_);
    due = impl_->pacer_.offer(pulses, now);
    impl_->pacerAlarm_.set(impl_->pacer_.nextWindow(now));
  }
  // A change leaves now, from this thread.
  if (due) impl_->send(*due);
}

void Transmitter::requestControl() {
  impl_->publish({link::ControlRequestAnswered{
      true, "RCOIP has no control right: the transmitter always steers"}});
}

TransmitterStatus Transmitter::transmitterStatus() const {
  MutexLock lock(impl_->mutex_);
  return impl_->monitor_.status();
}

}  // namespace wircam::rcoip
