#include "raw_transmitter.h"

#include <poll.h>
#include <sys/socket.h>

#include <array>
#include <stdexcept>

namespace wircam::testing {

RawTransmitter::RawTransmitter(uint16_t devicePort) {
  auto fd = connectTcp(SocketAddress::loopback(devicePort));
  if (!fd) throw std::runtime_error(fd.error());
  tcp_ = std::move(*fd);
  auto status = bindUdp(SocketAddress::loopback(0));
  if (!status) throw std::runtime_error(status.error());
  status_ = std::move(*status);
}

uint16_t RawTransmitter::statusPort() const { return localAddress(status_.get()).port(); }

void RawTransmitter::send(const wirc::Message& message) {
  auto frame = wirc::encode(message);
  if (!frame) throw std::runtime_error(frame.error().message());
  sendRaw(*frame);
}

void RawTransmitter::sendRaw(const std::vector<uint8_t>& bytes) {
  ::send(tcp_.get(), bytes.data(), bytes.size(), MSG_NOSIGNAL);
}

std::optional<wirc::Message> RawTransmitter::receive(std::chrono::milliseconds timeout) {
  auto deadline = std::chrono::steady_clock::now() + timeout;
  while (queue_.empty() && tcp_.valid() && !closed_) {
    auto left = std::chrono::duration_cast<std::chrono::milliseconds>(
        deadline - std::chrono::steady_clock::now());
    if (left.count() <= 0) break;
    pollfd fd{tcp_.get(), POLLIN, 0};
    if (::poll(&fd, 1, static_cast<int>(left.count())) <= 0) break;
    std::array<uint8_t, 4096> buffer;
    ssize_t n = ::recv(tcp_.get(), buffer.data(), buffer.size(), 0);
    if (n <= 0) {
      closed_ = true;
      break;
    }
    parser_.feed(std::span(buffer.data(), static_cast<size_t>(n)),
                 [&](const Expected<wirc::Message, wirc::ProtocolError>& result) {
                   if (result) queue_.push_back(*result);
                 });
  }
  if (queue_.empty()) return std::nullopt;
  auto message = queue_.front();
  queue_.pop_front();
  return message;
}

std::optional<wirc::Wst> RawTransmitter::login(const std::string& name, uint8_t priority,
                                               const wirc::ChannelValues& failsafe) {
  send(wirc::Tl{.system = 0,
                .version = {1, 0},
                .priority = priority,
                .name = name,
                .statusPort = statusPort()});
  wirc::ChannelValues periods{};
  periods.fill(20000);
  send(wirc::Ccfg{periods});
  send(wirc::Fcfg{failsafe});
  for (int i = 0; i < 4; ++i) {  // ERR replies may come first
    auto message = receive();
    if (!message) return std::nullopt;
    if (auto* wst = std::get_if<wirc::Wst>(&*message)) return *wst;
  }
  return std::nullopt;
}

std::vector<uint8_t> receiveDatagram(int fd, std::chrono::milliseconds timeout,
                                     SocketAddress* from) {
  pollfd p{fd, POLLIN, 0};
  if (::poll(&p, 1, static_cast<int>(timeout.count())) <= 0) return {};
  std::vector<uint8_t> buffer(65536);
  sockaddr_in source{};
  socklen_t size = sizeof source;
  ssize_t n =
      ::recvfrom(fd, buffer.data(), buffer.size(), 0, reinterpret_cast<sockaddr*>(&source), &size);
  if (n < 0) return {};
  buffer.resize(static_cast<size_t>(n));
  if (from) *from = SocketAddress(source);
  return buffer;
}

}  // namespace wircam::testing
