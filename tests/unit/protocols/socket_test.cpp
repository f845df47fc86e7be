// Our sockets' ports are ours alone: no other socket, whatever options it
// sets, can bind the port of a stream, status or control socket and take
// its datagrams.
#include "common/socket.h"

#include <gtest/gtest.h>
#include <netinet/in.h>
#include <sys/socket.h>

#include <set>
#include <vector>

namespace wircam {
namespace {

// Another program's attempt to bind `port` on loopback.
bool anotherSocketCanBind(int type, uint16_t port, bool reuseAddress, bool reusePort) {
  UniqueFd fd(::socket(AF_INET, type | SOCK_CLOEXEC, 0));
  int on = 1;
  if (reuseAddress) setsockopt(fd.get(), SOL_SOCKET, SO_REUSEADDR, &on, sizeof on);
  if (reusePort) setsockopt(fd.get(), SOL_SOCKET, SO_REUSEPORT, &on, sizeof on);
  auto address = SocketAddress::loopback(port);
  return ::bind(fd.get(), address.raw(), address.size()) == 0;
}

TEST(Sockets, NoOtherSocketCanBindTheUdpPortWeHold) {
  auto ours = bindUdp(SocketAddress::loopback(0));
  ASSERT_TRUE(ours.has_value()) << ours.error();
  uint16_t port = localAddress(ours->get()).port();
  for (bool reuseAddress : {false, true})
    for (bool reusePort : {false, true})
      EXPECT_FALSE(anotherSocketCanBind(SOCK_DGRAM, port, reuseAddress, reusePort))
          << "SO_REUSEADDR " << reuseAddress << ", SO_REUSEPORT " << reusePort;
}

TEST(Sockets, NoOtherSocketCanBindTheEphemeralTcpPortWeListenOn) {
  auto ours = listenTcp(SocketAddress::loopback(0));
  ASSERT_TRUE(ours.has_value()) << ours.error();
  uint16_t port = localAddress(ours->get()).port();
  EXPECT_FALSE(anotherSocketCanBind(SOCK_STREAM, port, true, false));
  EXPECT_FALSE(anotherSocketCanBind(SOCK_STREAM, port, true, true));
}

TEST(Sockets, ManyEphemeralUdpBindsGetDistinctPorts) {
  // A recorder of 128 cameras: a stream, status and control socket each.
  std::vector<UniqueFd> sockets;
  std::set<uint16_t> ports;
  for (int i = 0; i < 3 * 128; ++i) {
    auto fd = bindUdp(SocketAddress::loopback(0));
    ASSERT_TRUE(fd.has_value()) << fd.error();
    ports.insert(localAddress(fd->get()).port());
    sockets.push_back(std::move(*fd));
  }
  EXPECT_EQ(ports.size(), sockets.size());
}

}  // namespace
}  // namespace wircam

namespace wircam {
namespace {

TEST(Sockets, AnIpv6AddressIsSaidToBeOneNotUnresolvable) {
  // wirc://[::1]:PORT failed as "cannot resolve '::1'" (a stranger's trial).
  auto six = SocketAddress::resolve("::1", 1984);
  ASSERT_FALSE(six);
  EXPECT_NE(six.error().find("IPv6"), std::string::npos) << six.error();
  ASSERT_TRUE(SocketAddress::resolve("127.0.0.1", 1984));
  ASSERT_TRUE(SocketAddress::resolve("localhost", 1984));
}

}  // namespace
}  // namespace wircam
