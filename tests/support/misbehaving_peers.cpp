#include "misbehaving_peers.h"

#include <poll.h>
#include <sys/eventfd.h>
#include <sys/socket.h>
#include <unistd.h>

#include <array>
#include <cerrno>
#include <optional>

#include "wirc/crc16.h"
#include "wirc/message_stream_parser.h"

namespace wircam::testing {

SilentPeer::SilentPeer() {
  listener_ = std::move(*listenTcp(SocketAddress::loopback(0)));
  port_ = localAddress(listener_.get()).port();
}

FullAcceptQueuePeer::FullAcceptQueuePeer() {
  auto fd = listenTcp(SocketAddress::loopback(0));
  listener_ = std::move(*fd);
  ::listen(listener_.get(), 0);
  port_ = localAddress(listener_.get()).port();
  // Connect until one no longer completes at once: the queue is full.
  for (int i = 0; i < 64; ++i) {
    auto filler = startConnectTcp(SocketAddress::loopback(port_));
    if (!filler) break;
    pollfd p{filler->get(), POLLOUT, 0};
    bool completed = ::poll(&p, 1, 100) > 0 && pendingError(filler->get()) == 0;
    fillers_.push_back(std::move(*filler));
    if (!completed) break;
  }
}

std::vector<uint8_t> bytesOf(const wirc::Message& message) { return *wirc::encode(message); }

std::vector<uint8_t> framed(uint8_t command, const std::vector<uint8_t>& body) {
  std::vector<uint8_t> frame(4 + body.size() + 2);
  frame[0] = wirc::kSync1;
  frame[1] = wirc::kSync2;
  frame[2] = command;
  frame[3] = static_cast<uint8_t>(body.size());
  std::copy(body.begin(), body.end(), frame.begin() + 4);
  frame.resize(4 + body.size());
  uint16_t crc = wirc::crc16Xmodem(std::span(frame).subspan(2));
  frame.push_back(static_cast<uint8_t>(crc >> 8));
  frame.push_back(static_cast<uint8_t>(crc & 0xFF));
  return frame;
}

ScriptedPeer::ScriptedPeer(PeerScript script) : script_(std::move(script)) {
  listener_ = std::move(*listenTcp(SocketAddress::loopback(0)));
  control_ = std::move(*bindUdp(SocketAddress::loopback(0)));
  port_ = localAddress(listener_.get()).port();
  wake_ = UniqueFd(eventfd(0, EFD_CLOEXEC));
  thread_ = std::thread([this] {
    for (;;) {
      std::array<pollfd, 2> fds = {pollfd{listener_.get(), POLLIN, 0},
                                   pollfd{wake_.get(), POLLIN, 0}};
      if (::poll(fds.data(), fds.size(), -1) <= 0 || (fds[1].revents & POLLIN)) return;
      UniqueFd connection(::accept(listener_.get(), nullptr, nullptr));
      if (!connection.valid()) continue;
      ++connections_;
      serve(std::move(connection));
    }
  });
}

void ScriptedPeer::play(PeerScript script) {
  std::lock_guard lock(mutex_);
  script_ = std::move(script);
}

std::vector<uint8_t> ScriptedPeer::wst(uint8_t connectionId) const {
  return bytesOf(
      wirc::Wst{.connectionId = connectionId, .cameraCount = 1, .controlPort = controlPort()});
}

void ScriptedPeer::serve(UniqueFd connection) {
  PeerScript script;
  {
    std::lock_guard lock(mutex_);
    script = script_;
  }
  auto woken = [&](int timeoutMs) {
    pollfd p{wake_.get(), POLLIN, 0};
    return ::poll(&p, 1, timeoutMs) > 0;
  };
  // The login: wait for the TL and learn where status reports go.
  wirc::MessageStreamParser parser;
  std::optional<uint16_t> statusPort;
  std::array<uint8_t, 1024> buffer;
  for (int i = 0; i < 100 && !statusPort; ++i) {
    pollfd p{connection.get(), POLLIN, 0};
    if (::poll(&p, 1, 20) <= 0) continue;
    ssize_t n = ::recv(connection.get(), buffer.data(), buffer.size(), 0);
    if (n <= 0) return;
    parser.feed(std::span(buffer.data(), static_cast<size_t>(n)), [&](const auto& message) {
      if (message)
        if (const auto* tl = std::get_if<wirc::Tl>(&*message)) statusPort = tl->statusPort;
    });
  }
  for (const auto& chunk : script.chunks) {
    ::send(connection.get(), chunk.data(), chunk.size(), MSG_NOSIGNAL);
    if (woken(20)) return;
  }
  for (int i = 0; statusPort && i < script.statusReports; ++i)
    sendDatagram(control_.get(), SocketAddress::loopback(*statusPort),
                 bytesOf(wirc::Psd{.batteryMillivolts = 7400}));
  // The flood goes on until the transmitter hangs up; without one, the
  // connection stays open and silent until then.
  for (;;) {
    if (woken(script.flood.empty() ? 50 : 0)) return;
    if (!script.flood.empty() &&
        ::send(connection.get(), script.flood.data(), script.flood.size(),
               MSG_NOSIGNAL | MSG_DONTWAIT) < 0 &&
        errno != EAGAIN)
      return;
    pollfd p{connection.get(), POLLIN, 0};
    if (::poll(&p, 1, 0) > 0 && ::recv(connection.get(), buffer.data(), buffer.size(), 0) <= 0)
      return;
  }
}

ScriptedPeer::~ScriptedPeer() {
  uint64_t one = 1;
  if (write(wake_.get(), &one, sizeof one) < 0) {
    // Cannot fail for a fresh eventfd.
  }
  thread_.join();
}

uint16_t deadPort() {
  auto fd = listenTcp(SocketAddress::loopback(0));
  return localAddress(fd->get()).port();
}

}  // namespace wircam::testing
