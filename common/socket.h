// Thin RAII over BSD sockets (IPv4, as the WiRC protocol is): an owned file
// descriptor, an address type, and the few set-ups wircam needs.
#pragma once

#include <netinet/in.h>

#include <cstdint>
#include <functional>
#include <span>
#include <string>

#include "common/expected.h"

namespace wircam {

class UniqueFd {
 public:
  UniqueFd() = default;
  explicit UniqueFd(int fd) : fd_(fd) {}
  UniqueFd(UniqueFd&& other) noexcept : fd_(other.release()) {}
  UniqueFd& operator=(UniqueFd&& other) noexcept {
    if (this != &other) reset(other.release());
    return *this;
  }
  UniqueFd(const UniqueFd&) = delete;
  UniqueFd& operator=(const UniqueFd&) = delete;
  ~UniqueFd() { reset(); }

  int get() const { return fd_; }
  bool valid() const { return fd_ >= 0; }
  int release() {
    int fd = fd_;
    fd_ = -1;
    return fd;
  }
  void reset(int fd = -1);

 private:
  int fd_ = -1;
};

class SocketAddress {
 public:
  SocketAddress() = default;
  explicit SocketAddress(const sockaddr_in& address) : address_(address) {}

  // "127.0.0.1" or a host name, resolved to IPv4.
  static Expected<SocketAddress, std::string> resolve(const std::string& host, uint16_t port);
  static SocketAddress loopback(uint16_t port);

  uint16_t port() const { return ntohs(address_.sin_port); }
  SocketAddress withPort(uint16_t port) const;
  bool sameHost(const SocketAddress& other) const {
    return address_.sin_addr.s_addr == other.address_.sin_addr.s_addr;
  }
  bool operator==(const SocketAddress& other) const {
    return sameHost(other) && address_.sin_port == other.address_.sin_port;
  }
  std::string toString() const;  // "127.0.0.1:1984"
  std::string host() const;

  const sockaddr* raw() const { return reinterpret_cast<const sockaddr*>(&address_); }
  socklen_t size() const { return sizeof address_; }

 private:
  sockaddr_in address_{.sin_family = AF_INET};
};

// Each returns a ready socket or an error naming the address and the cause.
Expected<UniqueFd, std::string> bindUdp(const SocketAddress& address);
Expected<UniqueFd, std::string> listenTcp(const SocketAddress& address);
Expected<UniqueFd, std::string> connectTcp(const SocketAddress& address);
// Non-blocking: the connection is under way (wait for writability, then
// read pendingError()) or already made.
Expected<UniqueFd, std::string> startConnectTcp(const SocketAddress& address);
// SO_ERROR: 0 once a non-blocking connect has succeeded.
int pendingError(int fd);

SocketAddress localAddress(int fd);
SocketAddress peerAddress(int fd);
bool setNonBlocking(int fd);
std::string errnoText(int error);

// One datagram; false when the kernel did not take it whole.
bool sendDatagram(int fd, const SocketAddress& to, std::span<const uint8_t> bytes);

// Reads what is waiting on a non-blocking UDP socket, at most `most`
// datagrams, so that a flood cannot starve the other work of an event loop;
// each goes to `handle` with its sender.
void receiveDatagrams(
    int fd, std::span<uint8_t> buffer, int most,
    const std::function<void(std::span<const uint8_t>, const SocketAddress&)>& handle);

}  // namespace wircam
