#include <poll.h>
#include <sys/eventfd.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <cerrno>
#include <cstring>
#include <deque>
#include <list>
#include <map>
#include <mutex>
#include <thread>

#include "devices/wirc/device_impl.h"
#include "wirc/message_stream_parser.h"
#include "wirc/mjpeg_packet.h"

namespace wircam::wirc {

using device_detail::Connection;
using std::chrono::duration_cast;
using std::chrono::milliseconds;

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
  // PCD are judged by when they arrived (the kernel's stamp), not by when
  // this process got round to reading them: a real device has a processor
  // of its own, the simulator shares one with the transmitter under test.
  int on = 1;
  setsockopt(control_.get(), SOL_SOCKET, SO_TIMESTAMPNS, &on, sizeof on);
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
    // PCD that arrived while this process waited for a processor count
    // before the watchdog looks.
    readPcds();
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
    if (fds[2].revents & POLLIN) readPcds();
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
    if (auto error = openListener()) {
      log("restart failed: " + *error);
    } else {
      ++localStats_.restartsDone;
      log("restarted as '" + name_ + "'");
    }
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
    auto period = scene_ ? scene_->frameInterval() : std::nullopt;
    if (!period)
      period =
          duration_cast<DeviceClock::duration>(std::chrono::duration<double>(1.0 / config_.fps));
    nextFrame_ += *period;
    if (nextFrame_ <= now) nextFrame_ = now + *period;  // skip ticks we were too slow for
  }
}

void Device::Impl::tickFrame(DeviceClock::time_point now) {
  if (lastTick_) {
    localStats_.maxTickGap =
        std::max(localStats_.maxTickGap, duration_cast<milliseconds>(now - *lastTick_));
    // The battery drains with throttle (channel 2) away from neutral.
    double seconds = std::chrono::duration<double>(now - *lastTick_).count();
    double throttle = std::abs(static_cast<int>(localOutputs_.pulses[1]) - kPulseNeutral) / 500.0;
    if (localOutputs_.pulses[1] == 0) throttle = 0;
    batteryMillivolts_ = std::max<double>(config_.emptyBatteryMillivolts,
                                          batteryMillivolts_ - seconds * (0.2 + 4.0 * throttle));
  }
  lastTick_ = now;
  if (!scene_ || (streams_.empty() && scene_->waitsForViewer())) return;
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
  auto known = scene_ ? scene_->batteryMillivolts() : std::nullopt;
  psd.batteryMillivolts = known.value_or(static_cast<uint16_t>(batteryMillivolts_));
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

// When a datagram reached the socket, on the device's clock: the kernel's
// receive stamp (CLOCK_REALTIME) moved onto the steady clock by their
// present difference; `now` when there is no stamp.
static DeviceClock::time_point arrivalTime(msghdr& header, DeviceClock::time_point now) {
  for (cmsghdr* c = CMSG_FIRSTHDR(&header); c; c = CMSG_NXTHDR(&header, c)) {
    if (c->cmsg_level != SOL_SOCKET || c->cmsg_type != SO_TIMESTAMPNS) continue;
    timespec stamp{};
    std::memcpy(&stamp, CMSG_DATA(c), sizeof stamp);
    auto received =
        std::chrono::system_clock::time_point(duration_cast<std::chrono::system_clock::duration>(
            std::chrono::seconds(stamp.tv_sec) + std::chrono::nanoseconds(stamp.tv_nsec)));
    auto age = std::chrono::system_clock::now() - received;
    if (age < std::chrono::nanoseconds(0)) return now;
    return now - duration_cast<DeviceClock::duration>(age);
  }
  return now;
}

void Device::Impl::readPcds() {
  // Bounded, so that a flood of datagrams cannot hold the device's thread.
  for (int read = 0; read < 256; ++read) {
    sockaddr_in from{};
    iovec data{buffer_.data(), buffer_.size()};
    alignas(cmsghdr) char control[CMSG_SPACE(sizeof(timespec))];
    msghdr header{};
    header.msg_name = &from;
    header.msg_namelen = sizeof from;
    header.msg_iov = &data;
    header.msg_iovlen = 1;
    header.msg_control = control;
    header.msg_controllen = sizeof control;
    ssize_t n = ::recvmsg(control_.get(), &header, MSG_DONTWAIT);
    if (n < 0) return;
    // Stamps never run backwards from one PCD to the next.
    auto arrival = arrivalTime(header, DeviceClock::now());
    if (lastPcd_) arrival = std::max(arrival, *lastPcd_);
    readPcd(std::span(buffer_.data(), static_cast<size_t>(n)), from, arrival);
  }
}

void Device::Impl::readPcd(std::span<const uint8_t> datagram, const sockaddr_in& from,
                           DeviceClock::time_point now) {
  auto message = decode(datagram);
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
  if (scene_) scene_->pcdReceived(now, localOutputs_.pulses);
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
