// The BTEMP controller's search for its robot and its registration, without
// I/O: datagrams and deadlines come in with their time, actions go out
// (probe, send, start the commands, tell the listeners) with the next
// deadline. Probing and RCTR repeat every second; PIAK from a robot starts
// the registration at once, RCAK ends it; silence for the keepalive timeout
// starts the search again where the robot was. The controller drives it on
// the event loop; unit tests drive it with a fake clock.
#pragma once

#include <chrono>
#include <optional>
#include <span>
#include <string>
#include <variant>
#include <vector>

#include "btemp/btemp_messages.h"
#include "common/socket.h"
#include "link/event_loop.h"
#include "link/reject_tally.h"
#include "link/vehicle_link.h"

namespace wircam::btemp {

struct ControllerStatus : link::LinkStatus {
  std::optional<NodeInfo> robot;
  std::optional<Pins> lastPins;
  uint64_t videoSegments = 0;     // recognised and ignored
  uint64_t foreignDatagrams = 0;  // from anyone but the robot: ignored
};

namespace registration {
// PING `host` (empty: the broadcast ports) from `port` on.
struct Probe {
  std::string host;
  uint16_t port;
};
struct Send {
  Message message;
  SocketAddress to;
};
// Registered: the paced commands start now.
struct StartCommands {};
struct Emit {
  link::LinkEvent event;
};
}  // namespace registration

using RegistrationAction = std::variant<registration::Probe, registration::Send,
                                        registration::StartCommands, registration::Emit>;
using RegistrationActions = std::vector<RegistrationAction>;

class Registration {
 public:
  using Clock = link::Clock;
  enum class Phase { Probing, Registering, Registered };
  static constexpr std::chrono::milliseconds kProbePeriod{1000};

  // Probes at `now` first. `host` and `port` are where to look (an empty
  // host: broadcast); `keepaliveTimeout` how long the robot may be silent.
  Registration(NodeInfo self, std::string host, uint16_t port,
               std::chrono::milliseconds keepaliveTimeout, Clock::time_point now);

  RegistrationActions onDeadline(Clock::time_point now);
  RegistrationActions onDatagram(const SocketAddress& from, std::span<const uint8_t> datagram,
                                 Clock::time_point now);
  std::optional<link::LinkEvent> rejectSummary(Clock::time_point now);
  Clock::time_point nextDeadline() const;

  Phase phase() const { return phase_; }
  // The robot commands go to, once registered.
  std::optional<SocketAddress> registeredRobot() const {
    return phase_ == Phase::Registered ? robot_ : std::nullopt;
  }
  const ControllerStatus& status() const { return status_; }
  void countCommandSent() { ++status_.commandsSent; }

 private:
  RegistrationActions handle(const Message& message, const SocketAddress& from,
                             Clock::time_point now);

  const NodeInfo self_;
  const std::string host_;
  const uint16_t port_;
  const std::chrono::milliseconds keepaliveTimeout_;
  std::optional<SocketAddress> namedHost_;  // until a robot answers, only it counts
  Phase phase_ = Phase::Probing;
  Clock::time_point deadline_;  // the next probe or RCTR
  Clock::time_point lastHeard_{};
  std::optional<SocketAddress> robot_;
  ControllerStatus status_;
  link::RejectTally rejected_;
};

}  // namespace wircam::btemp
