// One transmitter's login to one WiRC device, shared by every user in the
// process that names the same device (two wircsrc on cameras 0 and 1 plus a
// wirccontrol = one login, one connection ID, one PCD sender). It logs in,
// keeps the streams it was asked for running, reconnects after a loss, and
// while it holds the control right sends PCD at a fixed rate from its own
// thread, so a stalled pipeline stops the vehicle but never loses the link.
#pragma once

#include <chrono>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "common/socket.h"
#include "wirc/messages.h"

namespace wircam::wirc {

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
  double pcdRate = 50;                        // Hz while holding the control right
  std::chrono::milliseconds commandTtl{250};  // older commands give way to neutral
  std::chrono::milliseconds loginTimeout{3000};
  bool reconnect = true;

  // Sessions are shared by this key: the device's address, or the discovery
  // request when no host is named.
  std::string key() const;
};

enum class SessionState { Connecting, LoggedIn, Reconnecting, Failed, Closed };
const char* sessionStateName(SessionState state);

struct SessionStatus {
  SessionState state = SessionState::Connecting;
  std::string error;  // why the last attempt failed, if it did
  std::string deviceAddress;
  std::string deviceName;
  uint8_t connectionId = 0;
  uint8_t cameraCount = 0;
  bool hasControl = false;
  std::optional<Psd> lastStatus;
  uint64_t logins = 0;  // 1 after the first login, +1 per reconnect
  uint64_t pcdSent = 0;
  uint64_t errorsReceived = 0;
};

struct TransmitterInfo {
  uint8_t connectionId = 0;
  uint8_t priority = 0;
  std::string name;
};

class TransmitterSession {
 public:
  // The process-wide session for this device, created on first use and
  // logged out when the last user lets go.
  static std::shared_ptr<TransmitterSession> acquire(const SessionConfig& config);

  ~TransmitterSession();
  TransmitterSession(const TransmitterSession&) = delete;
  TransmitterSession& operator=(const TransmitterSession&) = delete;

  // Blocks until logged in; the error says why not (no device, refused...).
  std::optional<std::string> waitLoggedIn(std::chrono::milliseconds timeout);
  SessionStatus status() const;
  // status().logins without copying the rest: cheap enough for every packet.
  uint64_t logins() const;
  const SessionConfig& config() const;
  // The device's address once known (for filtering the stream's sender).
  std::optional<SocketAddress> deviceAddress() const;

  // Streams are remembered and started again after a reconnect.
  void startStream(uint8_t camera, uint16_t port);
  void stopStream(uint8_t camera);

  // The pulses to send while holding the control right. Values outside
  // 800..2200 are clamped here: nothing out of range ever leaves.
  void setCommand(const ChannelValues& pulses);

  // Control-connection requests; replies arrive as events and in status().
  void requestControl(uint8_t connectionId);
  std::optional<std::vector<TransmitterInfo>> listTransmitters(std::chrono::milliseconds timeout);
  // CCFG/FCFG/DCFG/WCFG/EXTOUT/FWUP; the ERR the device answers, if any
  // within `timeout`, is returned.
  std::optional<Err> sendConfiguration(const Message& message, std::chrono::milliseconds timeout);

  // Human-readable events (logins, losses, ERR, control changes), from the
  // session's thread. Returns an id for removeListener.
  using Listener = std::function<void(const std::string& event)>;
  int addListener(Listener listener);
  void removeListener(int id);

  class Impl;

 private:
  explicit TransmitterSession(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

}  // namespace wircam::wirc
