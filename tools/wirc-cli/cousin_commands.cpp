#include "cousin_commands.h"

#include <condition_variable>
#include <cstdio>
#include <memory>
#include <mutex>
#include <thread>

#include "btemp/btemp_controller.h"
#include "btemp/btemp_probe.h"
#include "common/expected.h"
#include "rcoip/rcoip_transmitter.h"

namespace wircam::cli {

namespace {

using Clock = std::chrono::steady_clock;
using std::chrono::milliseconds;

std::string describeStatus(const link::Telemetry& t) {
  std::string text;
  char part[64];
  if (t.batteryVolts)
    std::snprintf(part, sizeof part, "battery %.2f V", *t.batteryVolts), text += part;
  if (t.rssi) text += std::string(text.empty() ? "" : ", ") + "RSSI " + std::to_string(*t.rssi);
  if (t.inputs)
    std::snprintf(part, sizeof part, "%sinputs 0x%x", text.empty() ? "" : ", ", *t.inputs),
        text += part;
  if (t.outputs) std::snprintf(part, sizeof part, ", outputs 0x%x", *t.outputs), text += part;
  if (!t.pdmDuty.empty()) {
    text += ", PDM duty";
    for (auto [pin, duty] : t.pdmDuty)
      text += " " + std::to_string(pin) + "=" + std::to_string(duty);
  }
  return text;
}

// A link for `o`, with every status report and link change printed as it
// comes, and a way to wait for the first report.
class Session {
 public:
  explicit Session(std::shared_ptr<link::VehicleLink> link) : link_(std::move(link)) {
    listener_ = link_->addListener([this](const link::LinkEvent& event) {
      if (const auto* report = std::get_if<link::TelemetryReceived>(&event)) {
        std::printf("status: %s\n", describeStatus(report->telemetry).c_str());
        std::fflush(stdout);
        std::lock_guard lock(mutex_);
        ++reports_;
      } else if (std::holds_alternative<link::StateChanged>(event) ||
                 std::holds_alternative<link::InputRejected>(event)) {
        std::fprintf(stderr, "wirc-cli: %s\n", link::describe(event).c_str());
      }
      changed_.notify_all();
    });
  }
  ~Session() { link_->removeListener(listener_); }

  bool waitFor(milliseconds timeout, bool needReport) {
    std::unique_lock lock(mutex_);
    return changed_.wait_for(lock, timeout, [&] {
      return needReport ? reports_ > 0 : link_->status().state == link::LinkState::Live;
    });
  }
  link::VehicleLink& link() { return *link_; }

 private:
  std::shared_ptr<link::VehicleLink> link_;
  int listener_ = 0;
  std::mutex mutex_;
  std::condition_variable changed_;
  int reports_ = 0;
};

Expected<std::shared_ptr<link::VehicleLink>, std::string> open(const CousinOptions& o) {
  if (o.protocol == "rcoip") {
    if (o.host.empty()) return unexpected(std::string("RCOIP has no discovery: give --host"));
    auto link = rcoip::Transmitter::acquire(
        {.host = o.host, .port = o.port ? o.port : rcoip::kDefaultReceiverPort});
    if (!link) return unexpected(link.error());
    return std::shared_ptr<link::VehicleLink>(*link);
  }
  auto link = btemp::Controller::acquire({.host = o.host,
                                          .port = o.port ? o.port : btemp::kDefaultPort,
                                          .broadcastAddress = o.broadcastAddress});
  if (!link) return unexpected(link.error());
  return std::shared_ptr<link::VehicleLink>(*link);
}

}  // namespace

int driveCousin(const CousinOptions& o) {
  auto opened = open(o);
  if (!opened) return std::fprintf(stderr, "wirc-cli: %s\n", opened.error().c_str()), 1;
  Session session(*opened);
  // A BTEMP robot obeys only the controller it registered; RCOIP takes
  // commands at once (its replies come back while driving).
  if (o.protocol == "btemp" && !session.waitFor(o.timeout, false)) {
    std::fprintf(stderr, "wirc-cli: no BTEMP robot registered within %lld ms (%s)\n",
                 static_cast<long long>(o.timeout.count()), session.link().status().reason.c_str());
    return 1;
  }
  link::Pulses pulses = link::neutralPulses();
  pulses[0] = static_cast<uint16_t>(o.steering);
  pulses[1] = static_cast<uint16_t>(o.throttle);
  auto end = Clock::now() + std::chrono::duration<double>(o.seconds);
  while (Clock::now() < end) {
    session.link().setCommand(pulses);
    std::this_thread::sleep_for(milliseconds(50));
  }
  session.link().setCommand(link::neutralPulses());
  auto status = session.link().status();
  std::fprintf(stderr, "wirc-cli: drove %.1f s, %llu commands sent, then neutral\n", o.seconds,
               static_cast<unsigned long long>(status.commandsSent));
  return 0;
}

int infoCousin(const CousinOptions& o) {
  auto opened = open(o);
  if (!opened) return std::fprintf(stderr, "wirc-cli: %s\n", opened.error().c_str()), 1;
  Session session(*opened);
  // RCOIP answers only commands: the link's keepalive (neutral) asks.
  if (!session.waitFor(o.timeout, true)) {
    std::fprintf(stderr, "wirc-cli: no status report within %lld ms (%s)\n",
                 static_cast<long long>(o.timeout.count()), session.link().status().reason.c_str());
    return 1;
  }
  auto status = session.link().status();
  std::printf("protocol      %s\nvehicle       %s\nlink          %s\n", o.protocol.c_str(),
              status.vehicleAddress.c_str(), link::linkStateName(status.state));
  if (o.protocol == "btemp") {
    auto robot = std::static_pointer_cast<btemp::Controller>(*opened)->controllerStatus().robot;
    if (robot)
      std::printf("robot         %s (%s)\n", btemp::formatGuid(robot->node).c_str(),
                  btemp::nodeTypeName(btemp::nodeTypeOf(robot->flags)));
  }
  return 0;
}

int discoverBtemp(const CousinOptions& o) {
  auto found = btemp::discoverRobots(o.timeout, o.host, o.port ? o.port : btemp::kDefaultPort,
                                     o.broadcastAddress);
  if (!found) return std::fprintf(stderr, "wirc-cli: %s\n", found.error().c_str()), 1;
  std::printf("%-21s %-32s %s\n", "ADDRESS", "GUID", "TYPE");
  for (const auto& robot : *found)
    std::printf("%-21s %-32s %s\n", robot.address.toString().c_str(),
                btemp::formatGuid(robot.node.node).c_str(),
                btemp::nodeTypeName(btemp::nodeTypeOf(robot.node.flags)));
  return found->empty() ? 1 : 0;
}

}  // namespace wircam::cli
