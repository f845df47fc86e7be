// What steers the simulated car when it is not WiRC's PCD: an RCOIP receiver
// or a BTEMP robot on its own UDP port (wirc-sim --control), each one of
// these. The camera still streams over WiRC MJPEG.
#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <string>

#include "common/expected.h"
#include "devices/wirc/device.h"

namespace wircam::sim {

class VehicleControl {
 public:
  virtual ~VehicleControl() = default;
  // What the vehicle puts out at `now` (the failsafe once commands stopped).
  virtual wirc::ChannelOutputs outputs(wirc::DeviceClock::time_point now) = 0;
  virtual uint16_t port() const = 0;
  virtual std::string description() const = 0;    // "RCOIP receiver"
  virtual std::string summary() const = 0;        // one line of counters
  virtual uint64_t commandsReceived() const = 0;  // valid ones, from the controller
};

// "wirc" gives no VehicleControl (the device's own PCD steers); an unset
// port is the protocol's default.
Expected<std::unique_ptr<VehicleControl>, std::string> startVehicleControl(
    const std::string& protocol, const std::string& bindAddress, std::optional<uint16_t> port,
    wirc::Device::Logger logger);

}  // namespace wircam::sim
