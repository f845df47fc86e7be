// An RCOIP receiver that behaves like the reference one (RCKit's RCRx): it
// obeys the channel bytes of any transmitter, answers a command with its
// status at most once per reply interval and only to that command's sender,
// and fails safe (neutral, "failsafe" set) when commands stop for the fail
// interval. wirc-sim drives its car with it; tests use it as the vehicle.
#pragma once

#include <chrono>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>

#include "common/expected.h"
#include "link/channel_byte_map.h"
#include "link/event_loop.h"
#include "rcoip/rcoip_messages.h"
#include "vehicle_control.h"

namespace wircam::rcoip {

struct ReceiverConfig {
  std::string bindAddress = "127.0.0.1";
  uint16_t port = kDefaultReceiverPort;  // 0: pick a free one
  link::ChannelByteMap map;
  std::chrono::milliseconds replyInterval{kReplyIntervalMs};
  std::chrono::milliseconds failInterval{kFailIntervalMs};
  double batteryVolts = 11.1;
  uint8_t rssi = 200;
  bool replyWithoutRssi = false;  // the known 2-byte variant
};

struct ReceiverStats {
  uint64_t commands = 0;
  uint64_t rejected = 0;  // malformed datagrams
  uint64_t replies = 0;
  uint64_t failsafeEntries = 0;
};

class Receiver : public sim::VehicleControl {
 public:
  using Logger = std::function<void(const std::string&)>;
  static Expected<std::unique_ptr<Receiver>, std::string> start(ReceiverConfig config,
                                                                Logger logger = {});
  ~Receiver() override;
  Receiver(const Receiver&) = delete;
  Receiver& operator=(const Receiver&) = delete;

  uint16_t port() const override;
  wirc::ChannelOutputs outputs(link::Clock::time_point now) override;
  std::string description() const override { return "RCOIP receiver"; }
  std::string summary() const override;
  uint64_t commandsReceived() const override { return stats().commands; }
  ReceiverStats stats() const;

  class Impl;

 private:
  explicit Receiver(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

}  // namespace wircam::rcoip
