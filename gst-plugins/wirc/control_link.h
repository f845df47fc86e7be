// The vehicle link wirccontrol steers through, whatever the vehicle speaks:
// WiRC (the login shared with wircsrc), RCOIP or BTEMP. Also the `protocol`
// enum and the element message that carries the vehicle's status.
#pragma once

#include <gst/gst.h>

#include <chrono>
#include <memory>
#include <set>
#include <string>

#include "common/expected.h"
#include "link/vehicle_link.h"
#include "wirc/messages.h"

namespace wircam::gst {

enum class VehicleProtocol { Wirc = 0, Rcoip = 1, Btemp = 2 };
GType vehicleProtocolType();  // GEnum "GstWircVehicleProtocol": wirc, rcoip, btemp
const char* protocolName(VehicleProtocol protocol);
uint16_t defaultPort(VehicleProtocol protocol);  // 1984, 9048, 16980

struct ControlLinkSettings {
  VehicleProtocol protocol = VehicleProtocol::Wirc;
  std::string host;
  uint16_t port = 0;  // 0: the protocol's default
  double rateLimit = 50;
  std::chrono::milliseconds keepalive{100};
  bool keepaliveGiven = false;  // RCOIP keeps its own default (1000 ms) unless set
  std::chrono::milliseconds commandTtl{500};
  wirc::ChannelValues periods{};
  wirc::ChannelValues failsafe{};
  std::set<std::string> given;  // WiRC's shared settings this element set
};

Expected<std::shared_ptr<link::VehicleLink>, std::string> acquireControlLink(
    const ControlLinkSettings& settings, const std::string& user);

// A `wirc-vehicle` element message body for a status report: the fields
// the vehicle sent (battery-v, rssi, inputs, outputs, pdm-duty).
GstStructure* vehicleStatusStructure(const link::Telemetry& telemetry);

}  // namespace wircam::gst
