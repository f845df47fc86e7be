// A transmitter made of raw sockets and libwircproto's codec, with no
// session logic of its own: what the device tests use to speak to wirc-sim.
#pragma once

#include <chrono>
#include <deque>
#include <optional>
#include <string>

#include "common/socket.h"
#include "wirc/message_stream_parser.h"
#include "wirc/messages.h"

namespace wircam::testing {

class RawTransmitter {
 public:
  // Connects to the device's TCP port on loopback; also opens a UDP socket
  // for PSD (statusPort()).
  explicit RawTransmitter(uint16_t devicePort);

  bool connected() const { return tcp_.valid(); }
  void send(const wirc::Message& message);
  void sendRaw(const std::vector<uint8_t>& bytes);

  // The next message, or nullopt when none came within `timeout` or the
  // device closed the connection (see closedByDevice()).
  std::optional<wirc::Message> receive(std::chrono::milliseconds timeout = std::chrono::seconds(2));
  template <typename T>
  std::optional<T> receiveAs(std::chrono::milliseconds timeout = std::chrono::seconds(2)) {
    auto message = receive(timeout);
    if (!message || !std::holds_alternative<T>(*message)) return std::nullopt;
    return std::get<T>(*message);
  }
  bool closedByDevice() const { return closed_; }
  void close() { tcp_.reset(); }

  // TL, CCFG, FCFG; returns the WST (nullopt if none came).
  std::optional<wirc::Wst> login(const std::string& name, uint8_t priority,
                                 const wirc::ChannelValues& failsafe = wirc::neutralChannels());

  uint16_t statusPort() const;
  int statusSocket() const { return status_.get(); }

 private:
  UniqueFd tcp_;
  UniqueFd status_;
  wirc::MessageStreamParser parser_;
  std::deque<wirc::Message> queue_;
  bool closed_ = false;
};

// Waits up to `timeout` for a datagram on `fd`; empty when none came.
std::vector<uint8_t> receiveDatagram(int fd, std::chrono::milliseconds timeout,
                                     SocketAddress* from = nullptr);

}  // namespace wircam::testing
