// The dashboard's replies as positions, without I/O: each datagram is
// checked (sender, CRC, type, code, size, beacon) and what fails is
// counted and dropped; a beacon with no new position for `staleAfter` goes
// stale, with the reason, and comes back with its next one. PositionClient
// feeds it datagrams and deadlines with their time; unit tests do the same
// with a fake clock.
#pragma once

#include <chrono>
#include <cstdint>
#include <map>
#include <optional>
#include <span>
#include <string>
#include <variant>
#include <vector>

#include "common/socket.h"
#include "marvelmind/dashboard_clock.h"
#include "marvelmind/marvelmind_messages.h"

namespace wircam::marvelmind {

using Clock = std::chrono::steady_clock;

enum class Mode { kPoll, kStream };

struct ClientConfig {
  std::string host = "127.0.0.1";  // the dashboard
  uint16_t port = kDefaultDashboardPort;
  std::vector<uint8_t> beacons;  // the vehicle's beacon addresses, 1..254
  Mode mode = Mode::kPoll;
  uint16_t listenPort = 0;  // stream mode: where the dashboard pushes (0: any free one)
  double pollRate = 10;     // requests per second per beacon, poll mode
  Resolution resolution = Resolution::kCentimetres;
  TimestampUnit timestampUnit = TimestampUnit::kSixtyFourths;
  std::chrono::milliseconds staleAfter{1000};

  std::string dashboard() const { return host + ":" + std::to_string(port); }
};
// The problem with a configuration, if any.
std::optional<std::string> validate(const ClientConfig& config);

struct Position {
  uint8_t beacon = 0;
  double x = 0, y = 0, z = 0;  // metres
  double timestamp = 0;        // the dashboard's time of the measurement, seconds
  Clock::time_point measured;  // the same instant on this machine's clock
  Clock::time_point received;
};

struct PositionReceived {
  Position position;
};
struct PositionStale {
  uint8_t beacon;
  std::string reason;  // "no reply from the dashboard at ... for 1000 ms", ...
};
using PositionEvent = std::variant<PositionReceived, PositionStale>;

struct ClientStats {
  uint64_t requests = 0;
  uint64_t replies = 0;                      // valid replies for our beacons
  uint64_t positions = 0;                    // of those, new measurements
  uint64_t repeats = 0;                      // the dashboard's latest again (no new measurement)
  uint64_t foreign = 0;                      // datagrams from anyone but the dashboard
  std::map<std::string, uint64_t> rejected;  // by reason: "bad CRC", "wrong beacon", ...
  uint64_t rejectedTotal() const;
};

class BeaconTracker {
 public:
  // `dashboard` is where replies must come from (its host only in stream
  // mode); `localPort` where they arrive, for the reasons.
  BeaconTracker(const ClientConfig& config, SocketAddress dashboard, uint16_t localPort,
                Clock::time_point now);

  std::vector<PositionEvent> onDatagram(const SocketAddress& from,
                                        std::span<const uint8_t> datagram, Clock::time_point now);
  // nextDeadline() has come (or passed): the beacons due go stale.
  std::vector<PositionEvent> onDeadline(Clock::time_point now);
  // The earliest a beacon not yet stale goes stale; none while all are.
  std::optional<Clock::time_point> nextDeadline() const;

  void countRequests(uint64_t sent) { stats_.requests += sent; }
  const ClientStats& stats() const { return stats_; }
  std::optional<Position> latest(uint8_t beacon) const;

 private:
  struct Beacon {
    std::optional<uint32_t> lastTimestamp;  // raw, to tell a repeat from a new measurement
    std::optional<Position> latest;
    Clock::time_point lastNew;  // or the start
    bool stale = false;
  };

  bool fromDashboard(const SocketAddress& from) const;
  std::string silenceReason(uint8_t beacon, Clock::time_point now) const;

  const ClientConfig config_;
  const SocketAddress dashboard_;
  const uint16_t localPort_;
  ClientStats stats_;
  std::map<uint8_t, Beacon> beacons_;
  std::optional<Clock::time_point> lastReply_;
  DashboardClock clock_;
};

}  // namespace wircam::marvelmind
