// The BTEMP vehicle link: this process as the controller of one BTEMP robot.
// It finds the robot with PING/PIAK (probing a named host and port, or the
// broadcast ports 16980..17079, every second), registers with RCTR until
// RCAK, then sends CTRL every 100 ms (Impulse1, Impulse2, Throt1..4 =
// channels 1..4) and IDLE while nobody has given a command. Silence from the
// robot for the keepalive timeout (10 s) marks the link lost and starts the
// search again. PINS become telemetry; video segments are counted and
// ignored.
#pragma once

#include <chrono>
#include <memory>
#include <optional>
#include <string>

#include "btemp/btemp_messages.h"
#include "btemp/btemp_registration.h"
#include "common/expected.h"
#include "link/channel_byte_map.h"
#include "link/event_loop.h"
#include "link/shared_settings.h"
#include "link/vehicle_link.h"

namespace wircam::btemp {

struct ControllerConfig {
  std::string host;  // empty: probe the broadcast address
  uint16_t port = kDefaultPort;
  std::string broadcastAddress = "255.255.255.255";
  link::ChannelByteMap map;
  std::chrono::milliseconds ctrlPeriod{kCtrlPeriodMs};
  std::chrono::milliseconds keepaliveTimeout{kKeepaliveTimeoutMs};
  std::chrono::milliseconds commandTtl{250};  // older commands give way to the failsafe
  double rateLimit = 50;                      // changes per second at most
  link::Pulses failsafe = link::neutralPulses();

  std::string key() const;  // "btemp://HOST:PORT" or "btemp://broadcast"
  // What the link is opened with, by setting ("ctrl-period" → "100ms", ...).
  link::SettingValues settings() const;
};

class Controller : public link::VehicleLink {
 public:
  // The process-wide link to this robot, used by `user` (an element's name):
  // shared while the settings agree, a conflict naming both users otherwise.
  // It runs on `loop`.
  static Expected<std::shared_ptr<Controller>, std::string> acquire(
      const ControllerConfig& config, const std::string& user = "",
      link::EventLoop& loop = link::EventLoop::shared());
  ~Controller() override;
  Controller(const Controller&) = delete;
  Controller& operator=(const Controller&) = delete;

  void setCommand(const link::Pulses& pulses) override;
  // Registration is the control right: answered at once.
  void requestControl() override;
  link::LinkStatus status() const override { return controllerStatus(); }
  ControllerStatus controllerStatus() const;

  class Impl;

 private:
  Controller() = default;
  std::unique_ptr<Impl> impl_;
};

// A random GUID for this process's controller node.
Guid randomGuid();

}  // namespace wircam::btemp
