// The WiRC vehicle link: one transmitter's login to one WiRC device, shared
// by every user in the process that names the same device (two wircsrc on
// cameras 0 and 1 plus a wirccontrol = one login, one connection ID; the
// real device accepts one TCP connection per IP address). It runs on the
// process's event loop: discovery, a non-blocking connect and the login
// have one deadline, losses reconnect with backoff, PSD become telemetry,
// and PCD leave when the command changes or a keepalive is due.
#pragma once

#include <chrono>
#include <memory>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include "common/expected.h"
#include "common/socket.h"
#include "link/event_loop.h"
#include "link/vehicle_link.h"
#include "wirc/messages.h"

namespace wircam::wirc {

static_assert(std::is_same_v<ChannelValues, link::Pulses>);

struct SessionConfig {
  std::string host;  // empty: discover
  uint16_t port = kDefaultPort;
  std::string device;  // name or serial to pick when discovering
  std::string discoveryAddress = "255.255.255.255";
  std::string transmitterName = "wircam";
  uint8_t priority = 0;
  ChannelValues periods = [] {
    ChannelValues p{};
    p.fill(20000);
    return p;
  }();
  ChannelValues failsafe = neutralChannels();
  double pcdRate = 50;                        // Hz: the most commands per second (a rate limit)
  std::chrono::milliseconds keepalive{100};   // PCD repeat while nothing changes
  std::chrono::milliseconds commandTtl{250};  // older commands give way to the failsafe
  std::chrono::milliseconds loginTimeout{3000};
  // No status report (PSD, every 500 ms) for this long means the device is
  // gone even if TCP has not noticed (power cut, out of range).
  std::chrono::milliseconds linkTimeout{2000};
  // Malformed messages one connection may bring before the device is taken
  // for misbehaving: the connection is dropped and made again after backoff.
  uint32_t maxBadMessages = 100;
  bool reconnect = true;
  // The settings this user set, by property name ("transmitter-name",
  // "priority", "pcd-rate", "lost-timeout" for commandTtl, ...). The others
  // defer to another user's.
  std::set<std::string> given;

  // Sessions are shared by this key: the device's address, or the discovery
  // request when no host is named.
  std::string key() const;
};

// keepalive must stay well below the device's PCD timeout (200..2000 ms).
constexpr std::chrono::milliseconds kMaxKeepalive{400};

struct SessionStatus : link::LinkStatus {
  std::string deviceName;
  uint8_t connectionId = 0;
  uint8_t cameraCount = 0;
  std::optional<Psd> lastStatus;
  uint64_t errorsReceived = 0;
};

struct TransmitterInfo {
  uint8_t connectionId = 0;
  uint8_t priority = 0;
  std::string name;
};

// The spec's meaning of an ERR code ("busy", "unauthorised", ...).
const char* errorCodeMeaning(uint16_t code);

class TransmitterSession : public link::VehicleLink {
 public:
  // The process-wide link for this device, used by `user` (an element's
  // name) until the returned pointer is dropped; the last one logs out.
  // A setting `user` gave that another user gave differently is refused,
  // naming both; one that nobody gave is adopted, logging in again when
  // it changes the login. It runs on `loop` (a test may own one).
  static Expected<std::shared_ptr<TransmitterSession>, std::string> acquire(
      const SessionConfig& config, const std::string& user = "",
      link::EventLoop& loop = link::EventLoop::shared());

  ~TransmitterSession() override;
  TransmitterSession(const TransmitterSession&) = delete;
  TransmitterSession& operator=(const TransmitterSession&) = delete;

  void setCommand(const link::Pulses& pulses) override;
  // A thread that wakes anyway (wircsrc's receive loop, at each frame)
  // lends the link its turn: a keepalive that would fall due before its
  // next one (`untilNextTurn` from now) leaves now, from this thread, and
  // the link's timer moves to the keepalive after, so the event loop does
  // not wake for it. The timer still sends whatever no turn did: the gaps
  // between commands are the keepalive's at most, video or not. While the
  // session steers, the device's status reports waiting are read as a
  // keepalive leaves, so a listener may hear TelemetryReceived on this
  // thread.
  void shareTurn(std::chrono::steady_clock::duration untilNextTurn);
  void requestControl() override;
  link::LinkStatus status() const override;
  SessionStatus sessionStatus() const;
  // The device's address once known (for filtering the stream's sender).
  std::optional<SocketAddress> deviceAddress() const;

  // Streams are remembered and started again after a reconnect.
  void startStream(uint8_t camera, uint16_t port);
  void stopStream(uint8_t camera);

  // For command-line use: block until logged in (or failed); the error says
  // why not.
  std::optional<std::string> waitLoggedIn(std::chrono::milliseconds timeout);
  // AREQ for another transmitter; the answer comes as ControlRequestAnswered.
  void requestControlFor(uint8_t connectionId);
  std::optional<std::vector<TransmitterInfo>> listTransmitters(std::chrono::milliseconds timeout);
  // CCFG/FCFG/DCFG/WCFG/EXTOUT/FWUP; the ERR the device answers, if any
  // within `timeout`, is returned.
  std::optional<Err> sendConfiguration(const Message& message, std::chrono::milliseconds timeout);

  class Impl;

 private:
  TransmitterSession(const SessionConfig& config, link::EventLoop& loop);
  std::unique_ptr<Impl> impl_;
};

}  // namespace wircam::wirc
