// The RCOIP vehicle link: this process as the transmitter of one RCOIP
// receiver. Commands leave on every change and at least every `keepalive`
// (the receiver answers only commands, so they are sent from the start);
// the receiver's replies bring RSSI and battery; no reply for
// `failInterval` marks the link lost, and replies coming back make it live.
// RCOIP has no control right: the transmitter always steers.
#pragma once

#include <chrono>
#include <memory>
#include <optional>
#include <string>

#include "common/expected.h"
#include "link/channel_byte_map.h"
#include "link/event_loop.h"
#include "link/shared_settings.h"
#include "link/vehicle_link.h"
#include "rcoip/rcoip_messages.h"
#include "rcoip/reply_monitor.h"

namespace wircam::rcoip {

struct TransmitterConfig {
  std::string host = "127.0.0.1";
  uint16_t port = kDefaultReceiverPort;
  size_t channelCount = 8;  // channel bytes per command: WiRC channels 1..N
  link::ChannelByteMap map;
  std::chrono::milliseconds keepalive{kKeepaliveIntervalMs};
  std::chrono::milliseconds failInterval{kFailIntervalMs};
  std::chrono::milliseconds commandTtl{250};  // older commands give way to the failsafe
  double rateLimit = 50;                      // changes per second at most
  link::Pulses failsafe = link::neutralPulses();

  std::string key() const { return "rcoip://" + host + ":" + std::to_string(port); }
  // What the link is opened with, by setting ("channels" → "8", ...).
  link::SettingValues settings() const;
};

class Transmitter : public link::VehicleLink {
 public:
  // The process-wide link to this receiver, used by `user` (an element's
  // name): shared while the settings agree, a conflict naming both users
  // otherwise. It runs on `loop`.
  static Expected<std::shared_ptr<Transmitter>, std::string> acquire(
      const TransmitterConfig& config, const std::string& user = "",
      link::EventLoop& loop = link::EventLoop::shared());
  ~Transmitter() override;
  Transmitter(const Transmitter&) = delete;
  Transmitter& operator=(const Transmitter&) = delete;

  void setCommand(const link::Pulses& pulses) override;
  // Answered at once: there is no control right to ask for.
  void requestControl() override;
  link::LinkStatus status() const override { return transmitterStatus(); }
  TransmitterStatus transmitterStatus() const;

  class Impl;

 private:
  Transmitter() = default;
  std::unique_ptr<Impl> impl_;
};

}  // namespace wircam::rcoip
