#include "misbehaving_peers.h"

#include <poll.h>
#include <sys/eventfd.h>
#include <sys/socket.h>
#include <unistd.h>

#include <array>

#include "wirc/messages.h"

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

RefusingPeer::RefusingPeer(uint16_t code) {
  listener_ = std::move(*listenTcp(SocketAddress::loopback(0)));
  port_ = localAddress(listener_.get()).port();
  wake_ = UniqueFd(eventfd(0, EFD_CLOEXEC));
  thread_ = std::thread([this, code] {
    auto answer = *wirc::encode(wirc::Err{static_cast<uint8_t>(wirc::Command::Tl), code});
    std::vector<UniqueFd> connections;
    for (;;) {
      std::array<pollfd, 2> fds = {pollfd{listener_.get(), POLLIN, 0},
                                   pollfd{wake_.get(), POLLIN, 0}};
      if (::poll(fds.data(), fds.size(), -1) <= 0 || (fds[1].revents & POLLIN)) return;
      UniqueFd connection(::accept(listener_.get(), nullptr, nullptr));
      if (!connection.valid()) continue;
      std::array<uint8_t, 512> request;
      pollfd p{connection.get(), POLLIN, 0};
      if (::poll(&p, 1, 2000) > 0 &&
          ::recv(connection.get(), request.data(), request.size(), 0) > 0)
        ::send(connection.get(), answer.data(), answer.size(), MSG_NOSIGNAL);
      connections.push_back(std::move(connection));  // kept open: the client must act on ERR
    }
  });
}

RefusingPeer::~RefusingPeer() {
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
