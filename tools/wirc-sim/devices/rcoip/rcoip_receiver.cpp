#include "devices/rcoip/rcoip_receiver.h"

#include <sys/epoll.h>
#include <sys/socket.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <mutex>
#include <optional>

#include "common/mutex.h"
#include "common/socket.h"

namespace wircam::rcoip {

using link::Clock;
using link::EventLoop;

class Receiver::Impl {
 public:
  Impl(ReceiverConfig config, UniqueFd socket, Logger logger);
  ~Impl();
  void onReadable();
  void log(const std::string& line) {
    if (logger_) logger_(line);
  }
  // Leaves the outputs at the failsafe once commands stopped.
  void expire(Clock::time_point now) WIRCAM_REQUIRES(mutex_);

  const ReceiverConfig config_;
  UniqueFd socket_;
  Logger logger_;
  EventLoop& loop_ = EventLoop::shared();
  EventLoop::Id watch_ = 0;

  mutable Mutex mutex_;
  wirc::ChannelOutputs outputs_ WIRCAM_GUARDED_BY(mutex_);
  std::optional<Clock::time_point> lastCommand_ WIRCAM_GUARDED_BY(mutex_);
  std::optional<Clock::time_point> lastReply_ WIRCAM_GUARDED_BY(mutex_);
  ReceiverStats stats_ WIRCAM_GUARDED_BY(mutex_);
};

Receiver::Impl::Impl(ReceiverConfig config, UniqueFd socket, Logger logger)
    : config_(std::move(config)), socket_(std::move(socket)), logger_(std::move(logger)) {
  watch_ = loop_.watch(socket_.get(), EPOLLIN, [this](uint32_t) { onReadable(); });
}

Receiver::Impl::~Impl() { loop_.remove(watch_); }

void Receiver::Impl::expire(Clock::time_point now) {
  if (outputs_.failsafe || !lastCommand_ || now - *lastCommand_ <= config_.failInterval) return;
  outputs_ = wirc::ChannelOutputs{};
  ++stats_.failsafeEntries;
  log("RCOIP: no command for " + std::to_string(config_.failInterval.count()) +
      " ms: failsafe (neutral)");
}

void Receiver::Impl::onReadable() {
  std::array<uint8_t, 1500> buffer;
  receiveDatagrams(socket_.get(), buffer, 64, [&](auto datagram, const SocketAddress& from) {
    auto now = Clock::now();
    auto command = decodeCommand(datagram);
    bool reply = false;
    {
      MutexLock lock(mutex_);
      if (!command) {
        ++stats_.rejected;
        return;
      }
      expire(now);
      if (outputs_.failsafe) log("RCOIP: commands from " + from.toString());
      // Channels a command leaves out read as 0, as the text says.
      for (size_t channel = 1; channel <= link::kChannels; ++channel) {
        uint8_t byte = channel <= command->channels.size() ? command->channels[channel - 1] : 0;
        outputs_.pulses[channel - 1] = config_.map.toPulse(channel, byte);
      }
      outputs_.failsafe = false;
      lastCommand_ = now;
      ++stats_.commands;
      reply = !lastReply_ || now - *lastReply_ >= config_.replyInterval;
      if (reply) {
        lastReply_ = now;
        ++stats_.replies;
      }
    }
    if (!reply) return;
    Reply status{.battery = static_cast<uint8_t>(
                     std::lround(std::clamp(config_.batteryVolts / 15.0, 0.0, 1.0) * 255))};
    if (!config_.replyWithoutRssi) status.rssi = config_.rssi;
    sendDatagram(socket_.get(), from, encode(status));
  });
}

Expected<std::unique_ptr<Receiver>, std::string> Receiver::start(ReceiverConfig config,
                                                                 Logger logger) {
  auto address = SocketAddress::resolve(config.bindAddress, config.port);
  if (!address) return unexpected(address.error());
  auto socket = bindUdp(*address);
  if (!socket) return unexpected("RCOIP receiver: " + socket.error());
  setNonBlocking(socket->get());
  return std::unique_ptr<Receiver>(new Receiver(
      std::make_unique<Impl>(std::move(config), std::move(*socket), std::move(logger))));
}

Receiver::Receiver(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
Receiver::~Receiver() = default;

uint16_t Receiver::port() const { return localAddress(impl_->socket_.get()).port(); }

wirc::ChannelOutputs Receiver::outputs(Clock::time_point now) {
  MutexLock lock(impl_->mutex_);
  impl_->expire(now);
  return impl_->outputs_;
}

ReceiverStats Receiver::stats() const {
  MutexLock lock(impl_->mutex_);
  return impl_->stats_;
}

std::string Receiver::summary() const {
  auto s = stats();
  return "RCOIP              " + std::to_string(s.commands) + " commands (" +
         std::to_string(s.rejected) + " rejected), " + std::to_string(s.replies) + " replies, " +
         std::to_string(s.failsafeEntries) + " failsafe entries";
}

}  // namespace wircam::rcoip
