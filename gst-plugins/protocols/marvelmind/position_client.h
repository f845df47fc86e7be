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
#include "link/event_loop.h"
#include "marvelmind/beacon_tracker.h"
#include "marvelmind/marvelmind_messages.h"

namespace wircam::marvelmind {

class PositionClient {
 public:
  using Listener = std::function<void(const PositionEvent&)>;

  // `listener` runs on `loop`'s thread and must not block.
  static Expected<std::unique_ptr<PositionClient>, std::string> start(
      const ClientConfig& config, Listener listener,
      link::EventLoop& loop = link::EventLoop::shared());
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
