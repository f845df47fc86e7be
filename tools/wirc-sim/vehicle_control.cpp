#include "vehicle_control.h"

#include "btemp/btemp_robot.h"
#include "rcoip/rcoip_receiver.h"

namespace wircam::sim {

namespace {

wirc::ChannelOutputs channelOutputs(const link::Pulses& pulses, bool failsafe) {
  return {.pulses = pulses, .failsafe = failsafe};
}

class RcoipControl : public VehicleControl {
 public:
  explicit RcoipControl(std::unique_ptr<rcoip::Receiver> receiver)
      : receiver_(std::move(receiver)) {}
  wirc::ChannelOutputs outputs(wirc::DeviceClock::time_point now) override {
    auto out = receiver_->outputs(now);
    return channelOutputs(out.pulses, out.failsafe);
  }
  uint16_t port() const override { return receiver_->port(); }
  std::string description() const override { return "RCOIP receiver"; }
  uint64_t commandsReceived() const override { return receiver_->stats().commands; }
  std::string summary() const override {
    auto s = receiver_->stats();
    return "RCOIP              " + std::to_string(s.commands) + " commands (" +
           std::to_string(s.rejected) + " rejected), " + std::to_string(s.replies) + " replies, " +
           std::to_string(s.failsafeEntries) + " failsafe entries";
  }

 private:
  std::unique_ptr<rcoip::Receiver> receiver_;
};

class BtempControl : public VehicleControl {
 public:
  explicit BtempControl(std::unique_ptr<btemp::Robot> robot) : robot_(std::move(robot)) {}
  wirc::ChannelOutputs outputs(wirc::DeviceClock::time_point now) override {
    auto out = robot_->outputs(now);
    return channelOutputs(out.pulses, out.failsafe);
  }
  uint16_t port() const override { return robot_->port(); }
  std::string description() const override { return "BTEMP robot"; }
  uint64_t commandsReceived() const override { return robot_->stats().ctrl; }
  std::string summary() const override {
    auto s = robot_->stats();
    return "BTEMP              " + std::to_string(s.ctrl) + " CTRL (" +
           std::to_string(s.ctrlForeign) + " from unregistered, " + std::to_string(s.rejected) +
           " rejected), " + std::to_string(s.pings) + " PING, " + std::to_string(s.registrations) +
           " RCTR, " + std::to_string(s.pinsSent) + " PINS, " + std::to_string(s.failsafeEntries) +
           " failsafe entries";
  }

 private:
  std::unique_ptr<btemp::Robot> robot_;
};

}  // namespace

Expected<std::unique_ptr<VehicleControl>, std::string> startVehicleControl(
    const std::string& protocol, const std::string& bindAddress, std::optional<uint16_t> port,
    wirc::Device::Logger logger) {
  if (protocol == "rcoip") {
    auto receiver = rcoip::Receiver::start(
        {.bindAddress = bindAddress, .port = port.value_or(rcoip::kDefaultReceiverPort)}, logger);
    if (!receiver) return unexpected(receiver.error());
    return std::unique_ptr<VehicleControl>(new RcoipControl(std::move(*receiver)));
  }
  if (protocol == "btemp") {
    auto robot = btemp::Robot::start(
        {.bindAddress = bindAddress, .port = port.value_or(btemp::kDefaultPort)}, logger);
    if (!robot) return unexpected(robot.error());
    return std::unique_ptr<VehicleControl>(new BtempControl(std::move(*robot)));
  }
  return std::unique_ptr<VehicleControl>();
}

}  // namespace wircam::sim
