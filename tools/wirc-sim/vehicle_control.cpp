#include "vehicle_control.h"

#include "devices/btemp/btemp_robot.h"
#include "devices/rcoip/rcoip_receiver.h"

namespace wircam::sim {

Expected<std::unique_ptr<VehicleControl>, std::string> startVehicleControl(
    const std::string& protocol, const std::string& bindAddress, std::optional<uint16_t> port,
    wirc::Device::Logger logger) {
  if (protocol == "rcoip") {
    auto receiver = rcoip::Receiver::start(
        {.bindAddress = bindAddress, .port = port.value_or(rcoip::kDefaultReceiverPort)}, logger);
    if (!receiver) return unexpected(receiver.error());
    return std::unique_ptr<VehicleControl>(std::move(*receiver));
  }
  if (protocol == "btemp") {
    auto robot = btemp::Robot::start(
        {.bindAddress = bindAddress, .port = port.value_or(btemp::kDefaultPort)}, logger);
    if (!robot) return unexpected(robot.error());
    return std::unique_ptr<VehicleControl>(std::move(*robot));
  }
  return std::unique_ptr<VehicleControl>();
}

}  // namespace wircam::sim
