// Who may hold one of the web server's connections, and for how long: at
// most `maxOpen` at once and `maxPerAddress` from one client address (the
// rest are refused at once), and a connection with no request in progress
// for longer than `idleTimeout` is to be closed. "No request in progress"
// covers a connection silent since it was opened, one idle between
// requests, and one still sending a request's headers (half-open), however
// slowly. A request in progress (a download, a live stream, a WebSocket)
// is not idle: stalled writes have their own socket timeout.
//
// GLib-free and clock-free: times come from the caller, so the policy is
// tested in microseconds. Slots are given back by closed(), however the
// connection ended.
#pragma once

#include <chrono>
#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <vector>

namespace wircam::recorder {

class ConnectionSlots {
 public:
  using Clock = std::chrono::steady_clock;
  using Id = uint64_t;

  struct Limits {
    size_t maxOpen = 128;
    size_t maxPerAddress = 64;
    Clock::duration idleTimeout = std::chrono::seconds(10);
  };
  explicit ConnectionSlots(Limits limits) : limits_(limits) {}

  // A new connection from `address`: its slot, or nullopt (close it now).
  std::optional<Id> admit(const std::string& address, Clock::time_point now);
  // Its request's headers were read: busy until requestEnded().
  void requestStarted(Id id);
  // Its response ended; `upgraded` connections (WebSockets) stay busy.
  void requestEnded(Id id, Clock::time_point now);
  void upgraded(Id id);
  void closed(Id id);

  // The connections idle for longer than the timeout at `now` (each named
  // once: it is taken to be closing).
  std::vector<Id> expired(Clock::time_point now);

  size_t open() const { return connections_.size(); }
  const Limits& limits() const { return limits_; }
  size_t openFrom(const std::string& address) const;
  uint64_t refused() const { return refused_; }

 private:
  struct Connection {
    std::string address;
    Clock::time_point idleSince;
    bool busy = false;
    bool upgraded = false;
    bool closing = false;
  };
  Limits limits_;
  std::map<Id, Connection> connections_;
  std::map<std::string, size_t> perAddress_;
  Id next_ = 1;
  uint64_t refused_ = 0;
};

}  // namespace wircam::recorder
