#include "control_link.h"

#include "btemp/btemp_controller.h"
#include "rcoip/rcoip_transmitter.h"
#include "wirc/transmitter_session.h"

namespace wircam::gst {

GType vehicleProtocolType() {
  static GType type = [] {
    static const GEnumValue values[] = {
        {static_cast<gint>(VehicleProtocol::Wirc), "WiRC v1.3 (TCP login, PCD over UDP)", "wirc"},
        {static_cast<gint>(VehicleProtocol::Rcoip), "RCOIP v1 (channel bytes over UDP)", "rcoip"},
        {static_cast<gint>(VehicleProtocol::Btemp), "BTEMP (PING/RCTR/CTRL over UDP)", "btemp"},
        {0, nullptr, nullptr}};
    return g_enum_register_static("GstWircVehicleProtocol", values);
  }();
  return type;
}

const char* protocolName(VehicleProtocol protocol) {
  switch (protocol) {
    case VehicleProtocol::Wirc:
      return "wirc";
    case VehicleProtocol::Rcoip:
      return "rcoip";
    case VehicleProtocol::Btemp:
      return "btemp";
  }
  return "unknown";
}

uint16_t defaultPort(VehicleProtocol protocol) {
  switch (protocol) {
    case VehicleProtocol::Wirc:
      return wirc::kDefaultPort;
    case VehicleProtocol::Rcoip:
      return rcoip::kDefaultReceiverPort;
    case VehicleProtocol::Btemp:
      return btemp::kDefaultPort;
  }
  return 0;
}

namespace {

template <typename Link>
Expected<std::shared_ptr<link::VehicleLink>, std::string> upcast(
    Expected<std::shared_ptr<Link>, std::string> acquired) {
  if (!acquired) return unexpected(acquired.error());
  return std::shared_ptr<link::VehicleLink>(std::move(*acquired));
}

}  // namespace

Expected<std::shared_ptr<link::VehicleLink>, std::string> acquireControlLink(
    const ControlLinkSettings& s, const std::string& user) {
  uint16_t port = s.port ? s.port : defaultPort(s.protocol);
  switch (s.protocol) {
    case VehicleProtocol::Wirc:
      return upcast(wirc::TransmitterSession::acquire({.host = s.host,
                                                       .port = port,
                                                       .periods = s.periods,
                                                       .failsafe = s.failsafe,
                                                       .pcdRate = s.rateLimit,
                                                       .keepalive = s.keepalive,
                                                       .commandTtl = s.commandTtl,
                                                       .given = s.given},
                                                      user));
    case VehicleProtocol::Rcoip: {
      if (s.host.empty())
        return unexpected(
            std::string("RCOIP has no discovery: set host to the receiver's address"));
      rcoip::TransmitterConfig config{
          .host = s.host, .port = port, .commandTtl = s.commandTtl, .rateLimit = s.rateLimit};
      if (s.keepaliveGiven) config.keepalive = s.keepalive;
      return upcast(rcoip::Transmitter::acquire(config, user));
    }
    case VehicleProtocol::Btemp:
      return upcast(btemp::Controller::acquire({.host = s.host,
                                                .port = port,
                                                .ctrlPeriod = s.keepalive,
                                                .commandTtl = s.commandTtl,
                                                .rateLimit = s.rateLimit},
                                               user));
  }
  return unexpected(std::string("unknown protocol"));
}

GstStructure* vehicleStatusStructure(const link::Telemetry& t) {
  GstStructure* s = gst_structure_new_empty("wirc-vehicle");
  gst_structure_set(s, "event", G_TYPE_STRING, "status", nullptr);
  if (t.batteryVolts) gst_structure_set(s, "battery-v", G_TYPE_DOUBLE, *t.batteryVolts, nullptr);
  if (t.rssi) gst_structure_set(s, "rssi", G_TYPE_INT, *t.rssi, nullptr);
  if (t.inputs) gst_structure_set(s, "inputs", G_TYPE_UINT, *t.inputs, nullptr);
  if (t.outputs) gst_structure_set(s, "outputs", G_TYPE_UINT, *t.outputs, nullptr);
  if (!t.pdmDuty.empty()) {
    // pin → duty as a structure, so JSON readers see {"pin0": 128, ...}.
    GstStructure* duty = gst_structure_new_empty("pdm-duty");
    for (auto [pin, value] : t.pdmDuty)
      gst_structure_set(duty, ("pin" + std::to_string(pin)).c_str(), G_TYPE_UINT,
                        static_cast<guint>(value), nullptr);
    gst_structure_set(s, "pdm-duty", GST_TYPE_STRUCTURE, duty, nullptr);
    gst_structure_free(duty);
  }
  return s;
}

}  // namespace wircam::gst
