#include "misbehaving_peers.h"

#include <poll.h>
#include <sys/socket.h>

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

uint16_t deadPort() {
  auto fd = listenTcp(SocketAddress::loopback(0));
  return localAddress(fd->get()).port();
}

}  // namespace wircam::testing
