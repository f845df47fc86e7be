// When a vehicle link sends a command: at once when it changes (changes no
// closer together than the rate limit allows), otherwise a keepalive every `keepalive` so the
// vehicle's watchdog stays fed, and the failsafe once the command is older
// than `ttl` (a stalled pipeline stops the vehicle, the link stays up).
// Pure policy: the caller passes the time and does the sending.
#pragma once

#include <chrono>
#include <optional>

#include "link/vehicle_link.h"

namespace wircam::link {

// The spacing a rate limit of `perSecond` changes means (1..1000 per second).
std::chrono::microseconds intervalOf(double perSecond);

struct PacerConfig {
  std::chrono::milliseconds keepalive{100};
  std::chrono::microseconds minInterval{0};  // 1 / rate limit, between changes
  std::chrono::milliseconds ttl{250};
  Pulses failsafe = neutralPulses();
  // A keepalive may leave this much early, so that timers of many links
  // can share one wake-up (EventLoop::kCoalesce); never late.
  std::chrono::milliseconds keepaliveEarly{10};
};

class CommandPacer {
 public:
  using Clock = std::chrono::steady_clock;

  explicit CommandPacer(PacerConfig config) : config_(config) {}

  // A new command: the pulses to send now, if they should leave now.
  std::optional<Pulses> offer(const Pulses& pulses, Clock::time_point now);
  // From the link's timer: the pulses to send now, if any are due.
  std::optional<Pulses> poll(Clock::time_point now);
  // On a turn a thread takes anyway (a stream's receive loop), its next
  // expected `ahead` (at most half the keepalive is believed): the pulses
  // to send now, if a keepalive would fall due before that turn, so that
  // the link's timer need not wake for it.
  std::optional<Pulses> pollAhead(Clock::time_point now, Clock::duration ahead);
  // When poll() has something to send next, seen from `now`.
  Clock::time_point nextDeadline(Clock::time_point now) const;
  // The same as a window for a timer (link/alarm.h): from the first time
  // poll() would send (a keepalive may leave `keepaliveEarly` sooner) to
  // the deadline.
  struct Window {
    Clock::time_point earliest, latest;
  };
  Window nextWindow(Clock::time_point now) const;
  // Forget what was sent (a new login): the next poll sends at once.
  void restart();
  // Whether anyone has given a command yet (until then the failsafe goes).
  bool commanded() const { return command_.has_value(); }

  const PacerConfig& config() const { return config_; }

 private:
  Pulses effective(Clock::time_point now) const;
  std::optional<Pulses> sendIfDue(Clock::time_point now, bool keepaliveDue);

  PacerConfig config_;
  std::optional<Pulses> command_;
  Clock::time_point commandTime_{};
  std::optional<Pulses> lastSent_;
  Clock::time_point lastSentTime_{};
  std::optional<Clock::time_point> lastChangeTime_;  // the last send of a new value
};

}  // namespace wircam::link
