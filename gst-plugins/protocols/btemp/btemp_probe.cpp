#include "btemp/btemp_probe.h"

#include <poll.h>
#include <sys/socket.h>

#include <array>

namespace wircam::btemp {

Expected<UniqueFd, std::string> openBroadcastSocket() {
  auto socket = bindUdp(*SocketAddress::resolve("", 0));
  if (!socket) return unexpected(socket.error());
  int on = 1;
  setsockopt(socket->get(), SOL_SOCKET, SO_BROADCAST, &on, sizeof on);
  setNonBlocking(socket->get());
  return socket;
}

Expected<std::monostate, std::string> sendProbes(int fd, const std::string& host, uint16_t port,
                                                 const std::string& broadcastAddress,
                                                 const Ping& ping) {
  auto bytes = encode(ping);
  uint16_t first = host.empty() ? kProbePortFirst : port;
  uint16_t last = host.empty() ? kProbePortLast : port;
  auto base = SocketAddress::resolve(host.empty() ? broadcastAddress : host, first);
  if (!base) return unexpected(base.error());
  for (uint32_t p = first; p <= last; ++p)
    sendDatagram(fd, base->withPort(static_cast<uint16_t>(p)), bytes);
  return std::monostate{};
}

Expected<std::vector<FoundRobot>, std::string> discoverRobots(std::chrono::milliseconds timeout,
                                                              const std::string& host,
                                                              uint16_t port,
                                                              const std::string& broadcastAddress) {
  auto socket = openBroadcastSocket();
  if (!socket) return unexpected(socket.error());
  using Clock = std::chrono::steady_clock;
  auto end = Clock::now() + timeout;
  auto nextProbe = Clock::now();
  std::vector<FoundRobot> found;
  while (Clock::now() < end) {
    if (Clock::now() >= nextProbe) {
      if (auto sent = sendProbes(socket->get(), host, port, broadcastAddress, Ping{}); !sent)
        return unexpected(sent.error());
      nextProbe += std::chrono::seconds(1);
    }
    auto wait = std::min(end, nextProbe) - Clock::now();
    pollfd p{socket->get(), POLLIN, 0};
    if (::poll(&p, 1,
               static_cast<int>(std::chrono::ceil<std::chrono::milliseconds>(wait).count())) <= 0)
      continue;
    std::array<uint8_t, 1500> buffer;
    sockaddr_in from{};
    socklen_t size = sizeof from;
    ssize_t n = ::recvfrom(socket->get(), buffer.data(), buffer.size(), MSG_DONTWAIT,
                           reinterpret_cast<sockaddr*>(&from), &size);
    if (n <= 0) continue;
    auto message = decode(std::span(buffer.data(), static_cast<size_t>(n)));
    if (!message || !std::holds_alternative<Piak>(*message)) continue;
    SocketAddress address(from);
    bool known = false;
    for (const auto& robot : found) known = known || robot.address == address;
    if (!known) found.push_back({address, std::get<Piak>(*message).node});
  }
  return found;
}

}  // namespace wircam::btemp
