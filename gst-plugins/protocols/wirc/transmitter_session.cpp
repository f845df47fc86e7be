#include "wirc/transmitter_session.h"

#include <poll.h>
#include <sys/eventfd.h>
#include <sys/socket.h>
#include <time.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <condition_variable>
#include <map>
#include <mutex>
#include <set>
#include <thread>

#include "wirc/discovery.h"
#include "wirc/message_stream_parser.h"

namespace wircam::wirc {

namespace {

using Clock = std::chrono::steady_clock;
using std::chrono::milliseconds;

constexpr milliseconds kFirstBackoff{200};
constexpr milliseconds kMaxBackoff{5000};

// FCFG's special values are not pulses; a PCD sends neutral for them.
ChannelValues pcdFallback(const ChannelValues& failsafe) {
  ChannelValues values = failsafe;
  for (auto& v : values)
    if (v < kPulseMin || v > kPulseMax) v = kPulseNeutral;
  return values;
}

}  // namespace

std::string SessionConfig::key() const {
  if (!host.empty()) return host + ":" + std::to_string(port);
  return "discover:" + device + "@" + discoveryAddress + ":" + std::to_string(port);
}

const char* sessionStateName(SessionState state) {
  switch (state) {
    case SessionState::Connecting:
      return "connecting";
    case SessionState::LoggedIn:
      return "logged-in";
    case SessionState::Reconnecting:
      return "reconnecting";
    case SessionState::Failed:
      return "failed";
    case SessionState::Closed:
      return "closed";
  }
  return "unknown";
}

class TransmitterSession::Impl {
 public:
  explicit Impl(SessionConfig config);
  ~Impl();

  void run();
  void runPcd();
  void emit(const std::string& event);
  bool sendControl(const Message& message);

  SessionConfig config_;
  std::atomic<bool> stopping_{false};
  UniqueFd wake_;
  UniqueFd psdSocket_;  // PSD arrive here
  UniqueFd pcdSocket_;  // PCD leave from here

  // Guards everything below; never held while blocking on the network.
  mutable std::mutex mutex_;
  std::condition_variable changed_;
  SessionStatus status_;
  std::optional<SocketAddress> device_;
  std::optional<SocketAddress> controlAddress_;
  std::map<uint8_t, uint16_t> streamPorts_;
  ChannelValues command_ = neutralChannels();
  Clock::time_point commandTime_{};
  std::vector<TransmitterInfo> transmitters_;
  bool listComplete_ = false;
  std::vector<Err> errors_;
  uint64_t failedAttempts_ = 0;
  std::map<int, Listener> listeners_;
  std::mutex emitMutex_;
  int nextListener_ = 1;

  // The TCP connection; sendMutex_ serialises writers from any thread.
  std::mutex sendMutex_;
  UniqueFd tcp_;

  std::thread io_;
  std::thread pacer_;

 private:
  std::optional<std::string> connectAndLogin();
  void serve();
  void handle(const Message& message);
  bool sleepInterruptibly(milliseconds duration);
};

TransmitterSession::Impl::Impl(SessionConfig config) : config_(std::move(config)) {
  wake_ = UniqueFd(eventfd(0, EFD_CLOEXEC | EFD_NONBLOCK));
  if (auto fd = bindUdp(*SocketAddress::resolve("", 0))) psdSocket_ = std::move(*fd);
  if (auto fd = bindUdp(*SocketAddress::resolve("", 0))) pcdSocket_ = std::move(*fd);
  io_ = std::thread([this] { run(); });
  pacer_ = std::thread([this] { runPcd(); });
}

TransmitterSession::Impl::~Impl() {
  stopping_ = true;
  uint64_t one = 1;
  if (write(wake_.get(), &one, sizeof one) < 0) {
    // Cannot fail for an eventfd below its maximum; the flag is set anyway.
  }
  changed_.notify_all();
  io_.join();
  pacer_.join();
}

void TransmitterSession::Impl::emit(const std::string& event) {
  // Held while listeners run, so that once removeListener() returns its
  // listener is never called again.
  std::lock_guard emitting(emitMutex_);
  std::vector<Listener> listeners;
  {
    std::lock_guard lock(mutex_);
    for (auto& [id, listener] : listeners_) listeners.push_back(listener);
  }
  for (auto& listener : listeners) listener(event);
}

bool TransmitterSession::Impl::sendControl(const Message& message) {
  auto frame = encode(message);
  if (!frame) {
    emit("not sent: " + frame.error().message());
    return false;
  }
  std::lock_guard lock(sendMutex_);
  if (!tcp_.valid()) return false;
  return ::send(tcp_.get(), frame->data(), frame->size(), MSG_NOSIGNAL) ==
         static_cast<ssize_t>(frame->size());
}

bool TransmitterSession::Impl::sleepInterruptibly(milliseconds duration) {
  std::unique_lock lock(mutex_);
  return !changed_.wait_for(lock, duration, [this] { return stopping_.load(); });
}

void TransmitterSession::Impl::run() {
  milliseconds backoff = kFirstBackoff;
  while (!stopping_) {
    auto error = connectAndLogin();
    if (!error) {
      backoff = kFirstBackoff;
      serve();
      if (stopping_) break;
      error = "connection to the device lost";
    }
    bool retry;
    {
      std::lock_guard lock(mutex_);
      ++failedAttempts_;
      status_.hasControl = false;
      status_.error = *error;
      retry = config_.reconnect;
      status_.state = retry ? SessionState::Reconnecting : SessionState::Failed;
    }
    changed_.notify_all();
    emit(*error + (retry ? "; retrying in " + std::to_string(backoff.count()) + " ms" : ""));
    if (!retry || !sleepInterruptibly(backoff)) break;
    backoff = std::min(backoff * 2, kMaxBackoff);
  }
  // Log out: stop the streams this session started, then close.
  std::set<uint8_t> cameras;
  {
    std::lock_guard lock(mutex_);
    for (const auto& [camera, port] : streamPorts_) cameras.insert(camera);
  }
  for (uint8_t camera : cameras) sendControl(Est{camera});
  {
    std::lock_guard lock(sendMutex_);
    if (tcp_.valid()) ::shutdown(tcp_.get(), SHUT_RDWR);
    tcp_.reset();
  }
  {
    std::lock_guard lock(mutex_);
    if (status_.state != SessionState::Failed) status_.state = SessionState::Closed;
    status_.hasControl = false;
  }
  changed_.notify_all();
}

std::optional<std::string> TransmitterSession::Impl::connectAndLogin() {
  SocketAddress device;
  std::string deviceName;
  if (config_.host.empty()) {
    auto found = discoverDevices(config_.loginTimeout, config_.discoveryAddress, config_.port);
    if (!found) return found.error();
    auto picked = pickDevice(*found, config_.device);
    if (!picked) return picked.error();
    device = picked->address;
    deviceName = picked->advertisement.name;
  } else {
    auto resolved = SocketAddress::resolve(config_.host, config_.port);
    if (!resolved) return resolved.error();
    device = *resolved;
  }
  auto fd = connectTcp(device);
  if (!fd) return fd.error() + " (is the device on and is " + device.toString() + " its address?)";
  {
    std::lock_guard lock(sendMutex_);
    tcp_ = std::move(*fd);
  }
  {
    std::lock_guard lock(mutex_);
    device_ = device;
    status_.deviceAddress = device.toString();
    status_.deviceName = deviceName;
  }

  sendControl(Tl{.system = static_cast<uint8_t>(SystemType::PcClient),
                 .version = {1, 0},
                 .priority = config_.priority,
                 .name = config_.transmitterName,
                 .statusPort = localAddress(psdSocket_.get()).port()});
  sendControl(Ccfg{config_.periods});
  sendControl(Fcfg{config_.failsafe});

  // Wait for WST; ERR on CCFG/FCFG only means another transmitter was first.
  MessageStreamParser parser;
  std::optional<Wst> wst;
  std::vector<Message> early;
  auto deadline = Clock::now() + config_.loginTimeout;
  std::array<uint8_t, 1024> buffer;
  while (!wst && !stopping_) {
    auto left = std::chrono::duration_cast<milliseconds>(deadline - Clock::now());
    if (left.count() <= 0) return "no WST from " + device.toString() + " within the login timeout";
    pollfd p{tcp_.get(), POLLIN, 0};
    if (::poll(&p, 1, static_cast<int>(left.count())) <= 0) continue;
    ssize_t n = ::recv(tcp_.get(), buffer.data(), buffer.size(), 0);
    if (n <= 0) return "the device closed the connection during login";
    parser.feed(std::span(buffer.data(), static_cast<size_t>(n)),
                [&](const Expected<Message, ProtocolError>& result) {
                  if (!result) return;
                  if (auto* w = std::get_if<Wst>(&*result); w && !wst)
                    wst = *w;
                  else
                    early.push_back(*result);
                });
  }
  if (stopping_) return "stopped";

  std::map<uint8_t, uint16_t> streams;
  {
    std::lock_guard lock(mutex_);
    status_.state = SessionState::LoggedIn;
    status_.error.clear();
    status_.connectionId = wst->connectionId;
    status_.cameraCount = wst->cameraCount;
    ++status_.logins;
    controlAddress_ = device.withPort(wst->controlPort);
    streams = streamPorts_;
  }
  changed_.notify_all();
  emit("logged in to " + device.toString() + " as connection " + std::to_string(wst->connectionId) +
       " (" + std::to_string(wst->cameraCount) + " cameras)");
  for (const auto& message : early) handle(message);
  for (auto [camera, port] : streams) sendControl(Stst{camera, port});
  return std::nullopt;
}

void TransmitterSession::Impl::serve() {
  MessageStreamParser parser;
  std::array<uint8_t, 2048> buffer;
  while (!stopping_) {
    std::array<pollfd, 3> fds = {pollfd{tcp_.get(), POLLIN, 0}, pollfd{psdSocket_.get(), POLLIN, 0},
                                 pollfd{wake_.get(), POLLIN, 0}};
    if (::poll(fds.data(), fds.size(), 1000) <= 0) continue;
    if (fds[1].revents & POLLIN) {
      ssize_t n = ::recv(psdSocket_.get(), buffer.data(), buffer.size(), 0);
      if (n > 0) {
        auto message = decode(std::span(buffer.data(), static_cast<size_t>(n)));
        if (message && std::holds_alternative<Psd>(*message)) {
          std::lock_guard lock(mutex_);
          status_.lastStatus = std::get<Psd>(*message);
        }
      }
    }
    if (fds[0].revents & (POLLIN | POLLHUP | POLLERR)) {
      ssize_t n = ::recv(tcp_.get(), buffer.data(), buffer.size(), 0);
      if (n <= 0) return;
      parser.feed(std::span(buffer.data(), static_cast<size_t>(n)),
                  [&](const Expected<Message, ProtocolError>& result) {
                    if (result)
                      handle(*result);
                    else
                      emit("from the device: " + result.error().message());
                  });
    }
  }
}

void TransmitterSession::Impl::handle(const Message& message) {
  std::string event;
  {
    std::lock_guard lock(mutex_);
    if (auto* agr = std::get_if<Agr>(&message)) {
      bool mine = agr->connectionId == status_.connectionId;
      switch (agr->notification) {
        case AccessNotification::Granted:
          status_.hasControl = true;
          event = "control right granted";
          break;
        case AccessNotification::Revoked:
          status_.hasControl = false;
          event = "control right revoked: '" + agr->name + "' has it now";
          break;
        case AccessNotification::Denied:
          event = "control right request denied";
          break;
        case AccessNotification::Notification:
          status_.hasControl = mine;
          event = "control right now with '" + agr->name + "'";
          break;
      }
    } else if (auto* err = std::get_if<Err>(&message)) {
      ++status_.errorsReceived;
      errors_.push_back(*err);
      if (errors_.size() > 16) errors_.erase(errors_.begin());
      event =
          "device answered ERR " + std::to_string(err->code) + " to " + commandName(err->command);
    } else if (auto* tlst = std::get_if<Tlst>(&message)) {
      if (listComplete_) transmitters_.clear();
      listComplete_ = false;
      transmitters_.push_back({tlst->connectionId, tlst->priority, tlst->name});
    } else if (std::holds_alternative<Tlend>(message)) {
      listComplete_ = true;
    }
  }
  changed_.notify_all();
  if (!event.empty()) emit(event);
}

void TransmitterSession::Impl::runPcd() {
  auto period = std::chrono::duration_cast<Clock::duration>(
      std::chrono::duration<double>(1.0 / std::clamp(config_.pcdRate, 1.0, 200.0)));
  auto fallback = *encode(Pcd{pcdFallback(config_.failsafe)});
  // The frame is encoded again only when the command changes.
  Bytes commandFrame;
  Clock::time_point encodedAt{};
  auto next = Clock::now();
  while (!stopping_) {
    next += period;
    if (next < Clock::now()) next = Clock::now() + period;  // fell behind: do not burst
    // A plain absolute sleep: the cheapest way to wake 50 times a second;
    // stop() waits at most one period for it.
    timespec wake{};
    auto sinceEpoch = std::chrono::duration_cast<std::chrono::nanoseconds>(next.time_since_epoch());
    wake.tv_sec = static_cast<time_t>(sinceEpoch.count() / 1000000000);
    wake.tv_nsec = static_cast<long>(sinceEpoch.count() % 1000000000);
    clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &wake, nullptr);
    if (stopping_) break;

    std::unique_lock lock(mutex_);
    if (!status_.hasControl || !controlAddress_) continue;
    if (commandTime_ != encodedAt) {
      commandFrame = *encode(Pcd{command_});  // clamped in setCommand: always valid
      encodedAt = commandTime_;
    }
    bool fresh = Clock::now() - commandTime_ <= config_.commandTtl;
    auto to = *controlAddress_;
    lock.unlock();
    bool sent = sendDatagram(pcdSocket_.get(), to, fresh ? commandFrame : fallback);
    lock.lock();
    if (sent) ++status_.pcdSent;
  }
}

std::shared_ptr<TransmitterSession> TransmitterSession::acquire(const SessionConfig& config) {
  static std::mutex registryMutex;
  static std::map<std::string, std::weak_ptr<TransmitterSession>> registry;
  std::lock_guard lock(registryMutex);
  auto& entry = registry[config.key()];
  if (auto existing = entry.lock()) return existing;
  std::shared_ptr<TransmitterSession> session(
      new TransmitterSession(std::make_unique<Impl>(config)));
  entry = session;
  return session;
}

TransmitterSession::TransmitterSession(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
TransmitterSession::~TransmitterSession() = default;

std::optional<std::string> TransmitterSession::waitLoggedIn(std::chrono::milliseconds timeout) {
  std::unique_lock lock(impl_->mutex_);
  bool done = impl_->changed_.wait_for(lock, timeout, [&] {
    return impl_->status_.state == SessionState::LoggedIn || impl_->failedAttempts_ > 0;
  });
  if (impl_->status_.state == SessionState::LoggedIn) return std::nullopt;
  if (!done) return "no login within " + std::to_string(timeout.count()) + " ms";
  return impl_->status_.error;
}

SessionStatus TransmitterSession::status() const {
  std::lock_guard lock(impl_->mutex_);
  return impl_->status_;
}

uint64_t TransmitterSession::logins() const {
  std::lock_guard lock(impl_->mutex_);
  return impl_->status_.logins;
}

const SessionConfig& TransmitterSession::config() const { return impl_->config_; }

std::optional<SocketAddress> TransmitterSession::deviceAddress() const {
  std::lock_guard lock(impl_->mutex_);
  return impl_->device_;
}

void TransmitterSession::startStream(uint8_t camera, uint16_t port) {
  {
    std::lock_guard lock(impl_->mutex_);
    impl_->streamPorts_[camera] = port;
  }
  impl_->sendControl(Stst{camera, port});
}

void TransmitterSession::stopStream(uint8_t camera) {
  {
    std::lock_guard lock(impl_->mutex_);
    impl_->streamPorts_.erase(camera);
  }
  impl_->sendControl(Est{camera});
}

void TransmitterSession::setCommand(const ChannelValues& pulses) {
  std::lock_guard lock(impl_->mutex_);
  for (size_t i = 0; i < kChannelCount; ++i)
    impl_->command_[i] = std::clamp(pulses[i], kPulseMin, kPulseMax);
  impl_->commandTime_ = Clock::now();
}

void TransmitterSession::requestControl(uint8_t connectionId) {
  impl_->sendControl(Areq{connectionId});
}

std::optional<std::vector<TransmitterInfo>> TransmitterSession::listTransmitters(
    std::chrono::milliseconds timeout) {
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
                                                         std::chrono::milliseconds timeout) {
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

int TransmitterSession::addListener(Listener listener) {
  std::lock_guard lock(impl_->mutex_);
  int id = impl_->nextListener_++;
  impl_->listeners_[id] = std::move(listener);
  return id;
}

void TransmitterSession::removeListener(int id) {
  std::lock_guard emitting(impl_->emitMutex_);
  std::lock_guard lock(impl_->mutex_);
  impl_->listeners_.erase(id);
}

}  // namespace wircam::wirc
