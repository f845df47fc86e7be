// The port of a device (or receiver) switched off, kept from every other
// socket until it comes back on it: the parallel tests' own ephemeral
// sockets took a freed port now and then, and the device could not come
// back.
// TCP bound but not listening (a connection is refused, as by a vehicle
// that is off) and UDP bound.
#pragma once

#include <sys/socket.h>

#include <cstdint>

#include "common/socket.h"

namespace wircam::testing {

class HeldPort {
 public:
  explicit HeldPort(uint16_t port) : port_(port) {
    auto address = SocketAddress::loopback(port);
    tcp_ = UniqueFd(::socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC, 0));
    int on = 1;  // over its connections' TIME_WAIT, as the device's listener
    setsockopt(tcp_.get(), SOL_SOCKET, SO_REUSEADDR, &on, sizeof on);
    if (::bind(tcp_.get(), address.raw(), address.size()) != 0) tcp_.reset();
    if (auto udp = bindUdp(address)) udp_ = std::move(*udp);
  }
  uint16_t port() const { return port_; }
  void release() {
    tcp_.reset();
    udp_.reset();
  }

 private:
  uint16_t port_;
  UniqueFd tcp_, udp_;
};

}  // namespace wircam::testing
