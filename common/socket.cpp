#include "common/socket.h"

#include <arpa/inet.h>
#include <fcntl.h>
#include <netdb.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>

namespace wircam {

void UniqueFd::reset(int fd) {
  if (fd_ >= 0) ::close(fd_);
  fd_ = fd;
}

std::string errnoText(int error) { return std::strerror(error); }

Expected<SocketAddress, std::string> SocketAddress::resolve(const std::string& host,
                                                            uint16_t port) {
  sockaddr_in address{.sin_family = AF_INET, .sin_port = htons(port)};
  if (host.empty()) {
    address.sin_addr.s_addr = htonl(INADDR_ANY);
    return SocketAddress(address);
  }
  if (inet_pton(AF_INET, host.c_str(), &address.sin_addr) == 1) return SocketAddress(address);
  // The protocols' devices are IPv4 (their discovery is a broadcast): an
  // IPv6 address is said to be one, not "cannot resolve".
  in6_addr six{};
  if (inet_pton(AF_INET6, host.c_str(), &six) == 1)
    return unexpected("'" + host + "' is an IPv6 address: devices are reached over IPv4");
  addrinfo hints{.ai_family = AF_INET};
  addrinfo* found = nullptr;
  int rc = getaddrinfo(host.c_str(), nullptr, &hints, &found);
  if (rc != 0 || !found) return unexpected("cannot resolve '" + host + "': " + gai_strerror(rc));
  address.sin_addr = reinterpret_cast<sockaddr_in*>(found->ai_addr)->sin_addr;
  freeaddrinfo(found);
  return SocketAddress(address);
}

SocketAddress SocketAddress::loopback(uint16_t port) {
  sockaddr_in address{.sin_family = AF_INET, .sin_port = htons(port)};
  address.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  return SocketAddress(address);
}

SocketAddress SocketAddress::withPort(uint16_t port) const {
  sockaddr_in address = address_;
  address.sin_port = htons(port);
  return SocketAddress(address);
}

std::string SocketAddress::host() const {
  char text[INET_ADDRSTRLEN] = {};
  inet_ntop(AF_INET, &address_.sin_addr, text, sizeof text);
  return text;
}

std::string SocketAddress::toString() const { return host() + ":" + std::to_string(port()); }

namespace {

Expected<UniqueFd, std::string> openSocket(int type, const SocketAddress& address) {
  UniqueFd fd(::socket(AF_INET, type | SOCK_CLOEXEC, 0));
  if (!fd.valid()) return unexpected("socket: " + errnoText(errno));
  // A TCP listener may take its port over from the connections of an
  // earlier one still in TIME_WAIT (a device restarted on its port; Linux
  // wants the flag on both), and the flag never lets a second socket bind a
  // listening port. Never a datagram socket: Linux lets another
  // SO_REUSEADDR socket bind the very same UDP port and take its datagrams,
  // and hands a new port-0 bind a port such a socket holds.
  if (type == SOCK_STREAM) {
    int on = 1;
    setsockopt(fd.get(), SOL_SOCKET, SO_REUSEADDR, &on, sizeof on);
  }
  if (::bind(fd.get(), address.raw(), address.size()) != 0)
    return unexpected("cannot bind " + address.toString() + ": " + errnoText(errno));
  return fd;
}

}  // namespace

Expected<UniqueFd, std::string> bindUdp(const SocketAddress& address) {
  return openSocket(SOCK_DGRAM, address);
}

Expected<UniqueFd, std::string> listenTcp(const SocketAddress& address) {
  auto fd = openSocket(SOCK_STREAM, address);
  if (fd && ::listen(fd->get(), 16) != 0)
    return unexpected("cannot listen on " + address.toString() + ": " + errnoText(errno));
  return fd;
}

Expected<UniqueFd, std::string> connectTcp(const SocketAddress& address) {
  UniqueFd fd(::socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC, 0));
  if (!fd.valid()) return unexpected("socket: " + errnoText(errno));
  if (::connect(fd.get(), address.raw(), address.size()) != 0)
    return unexpected("cannot connect to " + address.toString() + ": " + errnoText(errno));
  return fd;
}

Expected<UniqueFd, std::string> startConnectTcp(const SocketAddress& address) {
  UniqueFd fd(::socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC | SOCK_NONBLOCK, 0));
  if (!fd.valid()) return unexpected("socket: " + errnoText(errno));
  if (::connect(fd.get(), address.raw(), address.size()) != 0 && errno != EINPROGRESS)
    return unexpected("cannot connect to " + address.toString() + ": " + errnoText(errno));
  return fd;
}

int pendingError(int fd) {
  int error = 0;
  socklen_t size = sizeof error;
  if (getsockopt(fd, SOL_SOCKET, SO_ERROR, &error, &size) != 0) return errno;
  return error;
}

SocketAddress localAddress(int fd) {
  sockaddr_in address{};
  socklen_t size = sizeof address;
  getsockname(fd, reinterpret_cast<sockaddr*>(&address), &size);
  return SocketAddress(address);
}

SocketAddress peerAddress(int fd) {
  sockaddr_in address{};
  socklen_t size = sizeof address;
  getpeername(fd, reinterpret_cast<sockaddr*>(&address), &size);
  return SocketAddress(address);
}

bool setNonBlocking(int fd) {
  int flags = fcntl(fd, F_GETFL);
  return flags >= 0 && fcntl(fd, F_SETFL, flags | O_NONBLOCK) == 0;
}

bool sendDatagram(int fd, const SocketAddress& to, std::span<const uint8_t> bytes) {
  ssize_t sent = ::sendto(fd, bytes.data(), bytes.size(), MSG_NOSIGNAL, to.raw(), to.size());
  return sent == static_cast<ssize_t>(bytes.size());
}

void receiveDatagrams(
    int fd, std::span<uint8_t> buffer, int most,
    const std::function<void(std::span<const uint8_t>, const SocketAddress&)>& handle) {
  for (int taken = 0; taken < most; ++taken) {
    sockaddr_in from{};
    socklen_t size = sizeof from;
    ssize_t n = ::recvfrom(fd, buffer.data(), buffer.size(), MSG_DONTWAIT,
                           reinterpret_cast<sockaddr*>(&from), &size);
    if (n < 0) return;
    handle(buffer.first(static_cast<size_t>(n)), SocketAddress(from));
  }
}

}  // namespace wircam
