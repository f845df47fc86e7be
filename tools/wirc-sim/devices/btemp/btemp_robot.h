// A BTEMP robot: answers PING with PIAK and RCTR with RCAK, obeys the CTRL
// of the controller that registered (Throt1..4 → channels 1..4), answers
// CTRL with PINS (at most every `pinsInterval`) and fails safe when CTRL
// and IDLE stop for `failInterval`. wirc-sim drives its car with it; tests
// use it as the vehicle.
#pragma once

#include <chrono>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>

#include "btemp/btemp_messages.h"
#include "common/expected.h"
#include "link/channel_byte_map.h"
#include "link/event_loop.h"
#include "vehicle_control.h"

namespace wircam::btemp {

struct RobotConfig {
  std::string bindAddress = "127.0.0.1";
  uint16_t port = kDefaultPort;  // 0: pick a free one
  link::ChannelByteMap map;
  std::chrono::milliseconds pinsInterval{500};
  std::chrono::milliseconds failInterval{1000};
  uint32_t inputs = 0x1;  // what the input pins read
};

struct RobotStats {
  uint64_t pings = 0;
  uint64_t registrations = 0;
  uint64_t ctrl = 0;
  uint64_t ctrlForeign = 0;  // CTRL from a controller that did not register
  uint64_t rejected = 0;     // malformed datagrams
  uint64_t pinsSent = 0;
  uint64_t failsafeEntries = 0;
};

class Robot : public sim::VehicleControl {
 public:
  using Logger = std::function<void(const std::string&)>;
  static Expected<std::unique_ptr<Robot>, std::string> start(RobotConfig config,
                                                             Logger logger = {});
  ~Robot() override;
  Robot(const Robot&) = delete;
  Robot& operator=(const Robot&) = delete;

  uint16_t port() const override;
  wirc::ChannelOutputs outputs(link::Clock::time_point now) override;
  std::string description() const override { return "BTEMP robot"; }
  std::string summary() const override;
  uint64_t commandsReceived() const override { return stats().ctrl; }
  RobotStats stats() const;

  class Impl;

 private:
  explicit Robot(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

}  // namespace wircam::btemp
