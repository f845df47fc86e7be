// A client of the Marvelmind dashboard: the positions of the beacons a
// vehicle carries, on the process's one event loop. It polls the dashboard
// (a request per beacon at `pollRate`) or, in stream mode, listens for the
// replies a dashboard set up to push sends. Every datagram is checked (CRC,
// type, code, size, beacon, sender) and what fails is counted and dropped.
// A beacon with no new position for `staleAfter` goes stale, and comes
// back with its next one.
#pragma once

#include <chrono>
#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <variant>
#include <vector>

#include "common/expected.h"
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

class PositionClient {
 public:
  using Listener = std::function<void(const PositionEvent&)>;

  // `listener` runs on the event loop thread and must not block.
  static Expected<std::unique_ptr<PositionClient>, std::string> start(const ClientConfig& config,
                                                                      Listener listener);
  // Once it returns, the listener is not running and never runs again.
  ~PositionClient();
  PositionClient(const PositionClient&) = delete;
  PositionClient& operator=(const PositionClient&) = delete;

  uint16_t localPort() const;  // where replies arrive (the stream mode's listen port)
  ClientStats stats() const;
  // The newest position of a beacon, stale or not.
  std::optional<Position> latest(uint8_t beacon) const;

  class Impl;

 private:
  PositionClient() = default;
  std::unique_ptr<Impl> impl_;
};

// "5", "5,6": beacon addresses (1..254; 0 and 255 are broadcast addresses).
Expected<std::vector<uint8_t>, std::string> parseBeacons(const std::string& text);

}  // namespace wircam::marvelmind
