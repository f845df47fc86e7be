#include "devices/btemp/btemp_robot.h"

#include <sys/epoll.h>
#include <sys/socket.h>

#include <array>
#include <mutex>
#include <optional>

#include "btemp/btemp_controller.h"
#include "common/mutex.h"
#include "common/socket.h"

namespace wircam::btemp {

using link::Clock;
using link::EventLoop;

class Robot::Impl {
 public:
  Impl(RobotConfig config, UniqueFd socket, Logger logger);
  ~Impl() { loop_.remove(watch_); }
  void onReadable();
  // What to answer `message` from `from` with, if anything.
  std::optional<Message> obey(const Message& message, const SocketAddress& from,
                              Clock::time_point now) WIRCAM_REQUIRES(mutex_);
  void expire(Clock::time_point now) WIRCAM_REQUIRES(mutex_);
  Pins pins() const WIRCAM_REQUIRES(mutex_);
  void log(const std::string& line) {
    if (logger_) logger_(line);
  }

  const RobotConfig config_;
  const NodeInfo self_{randomGuid(), nodeFlags(NodeType::Robot)};
  UniqueFd socket_;
  Logger logger_;
  EventLoop& loop_ = EventLoop::shared();
  EventLoop::Id watch_ = 0;

  mutable Mutex mutex_;
  std::optional<SocketAddress> controller_ WIRCAM_GUARDED_BY(mutex_);
  wirc::ChannelOutputs outputs_ WIRCAM_GUARDED_BY(mutex_);
  std::array<uint8_t, 4> throttle_ WIRCAM_GUARDED_BY(mutex_){};
  std::optional<Clock::time_point> lastHeard_ WIRCAM_GUARDED_BY(mutex_);
  std::optional<Clock::time_point> lastPins_ WIRCAM_GUARDED_BY(mutex_);
  RobotStats stats_ WIRCAM_GUARDED_BY(mutex_);
};

Robot::Impl::Impl(RobotConfig config, UniqueFd socket, Logger logger)
    : config_(std::move(config)), socket_(std::move(socket)), logger_(std::move(logger)) {
  watch_ = loop_.watch(socket_.get(), EPOLLIN, [this](uint32_t) { onReadable(); });
}

void Robot::Impl::expire(Clock::time_point now) {
  if (outputs_.failsafe || !lastHeard_ || now - *lastHeard_ <= config_.failInterval) return;
  outputs_ = wirc::ChannelOutputs{};
  throttle_ = {};
  ++stats_.failsafeEntries;
  log("BTEMP: the controller went quiet: failsafe (neutral)");
}

Pins Robot::Impl::pins() const {
  // Four PDM outputs carry Throt1..4; an output pin reads set while its
  // channel is above neutral.
  Pins pins{.inputs = config_.inputs, .pdmMask = 0x0F};
  for (size_t i = 0; i < 4; ++i) {
    if (outputs_.pulses[i] > link::kPulseNeutral + 10) pins.outputs |= 1u << i;
    if (!outputs_.failsafe) pins.pdmActive |= 1u << i;
    pins.duty.push_back(throttle_[i]);
  }
  return pins;
}

std::optional<Message> Robot::Impl::obey(const Message& message, const SocketAddress& from,
                                         Clock::time_point now) {
  if (const auto* ping = std::get_if<Ping>(&message)) {
    ++stats_.pings;
    if (ping->sender && !wantsResponse(ping->sender->flags)) return std::nullopt;
    return Piak{self_};
  }
  if (std::holds_alternative<Rctr>(message)) {
    if (!controller_ || !(*controller_ == from))
      log("BTEMP: controller " + from.toString() + " registered");
    controller_ = from;
    lastHeard_ = now;
    ++stats_.registrations;
    return Rcak{};
  }
  bool ours = controller_ && *controller_ == from;
  if (const auto* ctrl = std::get_if<Ctrl>(&message)) {
    if (!ours) {
      ++stats_.ctrlForeign;
      return std::nullopt;
    }
    expire(now);
    if (outputs_.failsafe) log("BTEMP: CTRL from " + from.toString());
    ++stats_.ctrl;
    lastHeard_ = now;
    throttle_ = ctrl->throttle;
    for (size_t channel = 1; channel <= 4; ++channel)
      outputs_.pulses[channel - 1] = config_.map.toPulse(channel, ctrl->throttle[channel - 1]);
    outputs_.failsafe = false;
    if (lastPins_ && now - *lastPins_ < config_.pinsInterval) return std::nullopt;
    lastPins_ = now;
    ++stats_.pinsSent;
    return pins();
  }
  if (std::holds_alternative<Idle>(message) && ours) {
    lastHeard_ = now;
    if (lastPins_ && now - *lastPins_ < config_.pinsInterval) return Idle{};
    lastPins_ = now;
    ++stats_.pinsSent;
    return pins();
  }
  return std::nullopt;
}

void Robot::Impl::onReadable() {
  std::array<uint8_t, 2048> buffer;
  receiveDatagrams(socket_.get(), buffer, 64, [&](auto datagram, const SocketAddress& from) {
    auto message = decode(datagram);
    std::optional<Message> answer;
    {
      MutexLock lock(mutex_);
      if (!message) {
        ++stats_.rejected;
        return;
      }
      answer = obey(*message, from, Clock::now());
    }
    if (answer) sendDatagram(socket_.get(), from, encode(*answer));
  });
}

Expected<std::unique_ptr<Robot>, std::string> Robot::start(RobotConfig config, Logger logger) {
  auto address = SocketAddress::resolve(config.bindAddress, config.port);
  if (!address) return unexpected(address.error());
  auto socket = bindUdp(*address);
  if (!socket) return unexpected("BTEMP robot: " + socket.error());
  setNonBlocking(socket->get());
  return std::unique_ptr<Robot>(
      new Robot(std::make_unique<Impl>(std::move(config), std::move(*socket), std::move(logger))));
}

Robot::Robot(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
Robot::~Robot() = default;

uint16_t Robot::port() const { return localAddress(impl_->socket_.get()).port(); }

wirc::ChannelOutputs Robot::outputs(Clock::time_point now) {
  MutexLock lock(impl_->mutex_);
  impl_->expire(now);
  return impl_->outputs_;
}

RobotStats Robot::stats() const {
  MutexLock lock(impl_->mutex_);
  return impl_->stats_;
}

std::string Robot::summary() const {
  auto s = stats();
  return "BTEMP              " + std::to_string(s.ctrl) + " CTRL (" +
         std::to_string(s.ctrlForeign) + " from unregistered, " + std::to_string(s.rejected) +
         " rejected), " + std::to_string(s.pings) + " PING, " + std::to_string(s.registrations) +
         " RCTR, " + std::to_string(s.pinsSent) + " PINS, " + std::to_string(s.failsafeEntries) +
         " failsafe entries";
}

}  // namespace wircam::btemp
