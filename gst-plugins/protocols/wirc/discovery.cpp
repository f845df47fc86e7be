#include "wirc/discovery.h"

#include <poll.h>
#include <sys/socket.h>

#include <array>

namespace wircam::wirc {

Expected<UniqueFd, std::string> sendDiscoveryRequest(const SocketAddress& destination) {
  auto socket = bindUdp(*SocketAddress::resolve("", 0));
  if (!socket) return unexpected(socket.error());
  int on = 1;
  setsockopt(socket->get(), SOL_SOCKET, SO_BROADCAST, &on, sizeof on);
  setNonBlocking(socket->get());
  auto request =
      encode(Bcsd{.system = static_cast<uint8_t>(SystemType::PcClient), .version = {1, 0}});
  if (!sendDatagram(socket->get(), destination, *request))
    return unexpected("cannot send discovery to " + destination.toString() + ": " +
                      errnoText(errno));
  return socket;
}

std::optional<DiscoveredDevice> readDiscoveryAnswer(int fd) {
  std::array<uint8_t, 512> buffer;
  sockaddr_in from{};
  socklen_t size = sizeof from;
  ssize_t n = ::recvfrom(fd, buffer.data(), buffer.size(), MSG_DONTWAIT,
                         reinterpret_cast<sockaddr*>(&from), &size);
  if (n <= 0) return std::nullopt;
  auto message = decode(std::span(buffer.data(), static_cast<size_t>(n)));
  if (!message || !std::holds_alternative<Bcsa>(*message)) return std::nullopt;
  return DiscoveredDevice{SocketAddress(from), std::get<Bcsa>(*message)};
}

Expected<std::vector<DiscoveredDevice>, std::string> discoverDevices(
    std::chrono::milliseconds timeout, const std::string& target, uint16_t port) {
  auto destination = SocketAddress::resolve(target, port);
  if (!destination) return unexpected(destination.error());
  auto socket = sendDiscoveryRequest(*destination);
  if (!socket) return unexpected(socket.error());
  std::vector<DiscoveredDevice> found;
  auto deadline = std::chrono::steady_clock::now() + timeout;
  for (;;) {
    auto left = std::chrono::duration_cast<std::chrono::milliseconds>(
        deadline - std::chrono::steady_clock::now());
    if (left.count() <= 0) break;
    pollfd p{socket->get(), POLLIN, 0};
    if (::poll(&p, 1, static_cast<int>(left.count())) <= 0) break;
    auto answer = readDiscoveryAnswer(socket->get());
    if (!answer) continue;
    bool known = false;
    for (const auto& device : found) known = known || device.address == answer->address;
    if (!known) found.push_back(std::move(*answer));
  }
  return found;
}

Expected<DiscoveredDevice, std::string> pickDevice(const std::vector<DiscoveredDevice>& found,
                                                   const std::string& wanted) {
  if (found.empty()) return unexpected(std::string("no WiRC device answered discovery"));
  std::string names;
  for (const auto& device : found) {
    const auto& ad = device.advertisement;
    if (!wanted.empty() && (ad.name == wanted || ad.serial == wanted)) return device;
    names +=
        (names.empty() ? "" : ", ") + ad.name + " (" + ad.serial + ") at " + device.address.host();
  }
  if (wanted.empty() && found.size() == 1) return found[0];
  return unexpected(wanted.empty()
                        ? "several devices answered, pick one by name or serial: " + names
                        : "no device named '" + wanted + "'; found: " + names);
}

}  // namespace wircam::wirc
