// The WiRC login and session as a state machine that does no I/O, as
// rtpsession.c is under gstrtpsession.c: events come in with the time they
// happened (a deadline reached, the connection made or lost, a message, a
// status report); actions go out (discover, connect, send, close, aim the
// commands, tell the listeners) with the next deadline. TransmitterSession
// drives it on the event loop; unit tests drive it with a fake clock.
//
// One attempt: discovery (when no host is named) → TCP connect → TL, CCFG,
// FCFG → WST, all within login-timeout. A failure tries again after a
// backoff that doubles from 200 ms to 5 s and starts over once a login has
// stayed up for 10 s. Logged in, no status report for link-timeout is a
// loss; so are more than max-bad-messages malformed messages on one
// connection.
#pragma once

#include <chrono>
#include <deque>
#include <map>
#include <optional>
#include <string>
#include <variant>
#include <vector>

#include "common/socket.h"
#include "link/event_loop.h"
#include "link/vehicle_link.h"
#include "wirc/discovery.h"
#include "wirc/message_stream_parser.h"
#include "wirc/messages.h"
#include "wirc/transmitter_session.h"

namespace wircam::wirc {

namespace login {
// Send BCSD to `destination` and report the answers (onDiscoveryAnswer).
struct Discover {
  SocketAddress destination;
};
// Open a TCP connection (onConnected or onConnectionLost follow).
struct Connect {
  SocketAddress device;
};
struct Send {
  Message message;
};
// Close the TCP connection and any discovery under way.
struct Close {};
// PCD go to this address from now on; commands may start (the control
// right decides when they leave).
struct AimCommands {
  SocketAddress control;
};
// The control right came: the paced commands start now.
struct StartCommands {};
struct Emit {
  link::LinkEvent event;
};
}  // namespace login

using LoginAction = std::variant<login::Discover, login::Connect, login::Send, login::Close,
                                 login::AimCommands, login::StartCommands, login::Emit>;
using LoginActions = std::vector<LoginAction>;

class LoginMachine {
 public:
  using Clock = link::Clock;
  enum class Phase { Waiting, Discovering, Connecting, LoggingIn, LoggedIn, Closed };

  static constexpr std::chrono::milliseconds kFirstBackoff{200};
  static constexpr std::chrono::milliseconds kMaxBackoff{5000};
  // A login is only a success once the link has stayed up this long: a
  // device that misbehaves right after each login (a flood, a refusal of
  // the stream) would otherwise be logged in to every kFirstBackoff for ever.
  static constexpr std::chrono::milliseconds kHealthyLink{10000};
  // Discovery listens this long (at most) for the devices to answer.
  static constexpr std::chrono::milliseconds kDiscoveryWindow{1000};
  static constexpr std::chrono::milliseconds kRejectSummaryPeriod{1000};

  // The first attempt is due at `now`. `statusPort` is where this side
  // takes PSD (sent in TL).
  LoginMachine(SessionConfig config, uint16_t statusPort, Clock::time_point now);

  // --- Events ---
  // nextDeadline() has come (or passed).
  LoginActions onDeadline(Clock::time_point now);
  LoginActions onDiscoveryAnswer(DiscoveredDevice device, Clock::time_point now);
  LoginActions onConnected(Clock::time_point now);
  // The connection (or the discovery) could not be made, was closed, or failed.
  LoginActions onConnectionLost(const std::string& why, Clock::time_point now);
  LoginActions onMessage(const Message& message, Clock::time_point now);
  // The connection's parser counters after a read: malformed input is
  // summed up once a second and, past max-bad-messages, a loss.
  LoginActions onParserStats(const StreamParserStats& stats, Clock::time_point now);
  LoginActions onStatusReport(const SocketAddress& from, const Psd& psd, Clock::time_point now);
  // New settings the device must hear: log in again at once (no loss).
  LoginActions relogin(const std::string& why, Clock::time_point now);
  // Logging out: the streams stop, the connection closes, nothing more.
  LoginActions close();

  // --- Requests ---
  // Remembered, and started again after each login.
  LoginActions startStream(uint8_t camera, uint16_t port);
  LoginActions stopStream(uint8_t camera);
  LoginActions requestControl(uint8_t connectionId);
  // TLR: the answers (TLST…TLEND) fill transmitters().
  LoginActions listTransmitters();
  // Any message, while connected; the device's ERR land in errors().
  LoginActions send(const Message& message);
  // Whether the device has `camera` (of the count its WST gave).
  bool hasCamera(uint8_t camera) const;

  // --- State ---
  std::optional<Clock::time_point> nextDeadline() const;
  Phase phase() const { return phase_; }
  bool connected() const { return phase_ == Phase::LoggingIn || phase_ == Phase::LoggedIn; }
  const SessionStatus& status() const { return status_; }
  std::optional<SocketAddress> device() const { return device_; }
  std::optional<SocketAddress> controlAddress() const { return controlAddress_; }
  SessionConfig& config() { return config_; }
  uint64_t failedAttempts() const { return failedAttempts_; }
  bool transmitterListComplete() const { return listComplete_; }
  const std::vector<TransmitterInfo>& transmitters() const { return transmitters_; }
  const std::vector<Err>& errors() const { return errors_; }
  void clearErrors() { errors_.clear(); }
  void countCommandSent() { ++status_.commandsSent; }

 private:
  enum class Retry { AfterBackoff, AtOnceForNewSettings };
  LoginActions beginAttempt(Clock::time_point now);
  LoginActions finishDiscovery(Clock::time_point now);
  LoginActions connect(const SocketAddress& device, const std::string& name);
  LoginActions loggedIn(const Wst& wst, Clock::time_point now);
  LoginActions controlRight(const Agr& agr);
  LoginActions deviceError(const Err& err, Clock::time_point now);
  LoginActions fail(const std::string& why, Clock::time_point now,
                    Retry retry = Retry::AfterBackoff);
  std::string deviceText() const;

  SessionConfig config_;
  uint16_t statusPort_;
  Phase phase_ = Phase::Waiting;
  std::optional<Clock::time_point> attemptDeadline_;  // the phase's, or the next attempt's
  std::optional<Clock::time_point> discoveryEnds_;
  std::chrono::milliseconds backoff_ = kFirstBackoff;
  std::optional<Clock::time_point> liveSince_;  // the current login's
  Clock::time_point lastHeard_;                 // login, or the last PSD
  std::vector<DiscoveredDevice> found_;

  // Malformed input of the current connection.
  uint64_t rejectedThisConnection_ = 0;  // weighted: 64 garbage bytes count as one
  uint64_t rejectedUnreported_ = 0;      // since the last summary
  StreamParserStats reported_;           // the counters at the last summary
  Clock::time_point lastSummary_;

  SessionStatus status_;
  std::optional<SocketAddress> device_;
  std::optional<SocketAddress> controlAddress_;
  std::map<uint8_t, uint16_t> streamPorts_;
  std::vector<TransmitterInfo> transmitters_;
  bool listComplete_ = false;
  std::vector<Err> errors_;
  uint64_t failedAttempts_ = 0;
  // The connections named by AREQs sent and not answered yet, oldest first.
  // An AGR answers the oldest when it denies it or names that connection as
  // the controller: the AGR a login brings (control to the first
  // transmitter) is no answer to a request for another connection.
  std::deque<uint8_t> controlRequests_;
};

}  // namespace wircam::wirc
