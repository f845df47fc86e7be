// A TCP port free on loopback now, for a server a test or bench starts
// that cannot be told to pick its own (mosquitto, a recorder's --http given
// to a client before it starts). Another process may take it meanwhile:
// the kernel hands out ephemeral ports in turn, so that is rare.
#pragma once

#include <cstdint>

#include "common/socket.h"

namespace wircam::testing {

inline uint16_t freeLoopbackPort() {
  auto socket = listenTcp(SocketAddress::loopback(0));
  return socket ? localAddress(socket->get()).port() : uint16_t{0};
}

}  // namespace wircam::testing
