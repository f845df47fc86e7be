#include "link/command_pacer.h"

#include <algorithm>

namespace wircam::link {

std::chrono::microseconds intervalOf(double perSecond) {
  return std::chrono::microseconds(static_cast<int64_t>(1e6 / std::clamp(perSecond, 1.0, 1000.0)));
}

Pulses CommandPacer::effective(Clock::time_point now) const {
  if (!command_ || now - commandTime_ > config_.ttl) return config_.failsafe;
  return *command_;
}

std::optional<Pulses> CommandPacer::sendIfDue(Clock::time_point now, bool keepaliveDue) {
  Pulses wanted = effective(now);
  bool changed = !lastSent_ || wanted != *lastSent_;
  // The rate limit spaces changes, not a change and a keepalive: a change
  // right after a keepalive still leaves at once.
  bool allowed = !lastChangeTime_ || now - *lastChangeTime_ >= config_.minInterval;
  if (!(changed && allowed) && !keepaliveDue) return std::nullopt;
  if (changed) lastChangeTime_ = now;
  lastSent_ = wanted;
  lastSentTime_ = now;
  return wanted;
}

std::optional<Pulses> CommandPacer::offer(const Pulses& pulses, Clock::time_point now) {
  command_ = pulses;
  for (auto& pulse : *command_) pulse = std::clamp(pulse, kPulseMin, kPulseMax);
  commandTime_ = now;
  return sendIfDue(now, false);
}

std::optional<Pulses> CommandPacer::poll(Clock::time_point now) {
  return sendIfDue(now,
                   !lastSent_ || now - lastSentTime_ >= config_.keepalive - config_.keepaliveEarly);
}

std::optional<Pulses> CommandPacer::pollAhead(Clock::time_point now, Clock::duration ahead) {
  // Believed at most half the keepalive: a turn that comes sooner than
  // expected sends no more than two keepalives a period.
  Clock::duration early =
      std::clamp<Clock::duration>(ahead, config_.keepaliveEarly, config_.keepalive / 2);
  return sendIfDue(now, !lastSent_ || now - lastSentTime_ >= config_.keepalive - early);
}

CommandPacer::Clock::time_point CommandPacer::nextDeadline(Clock::time_point now) const {
  if (!lastSent_) return now;
  auto next = lastSentTime_ + config_.keepalive;
  // A change the rate limit holds back.
  if (effective(now) != *lastSent_)
    next = std::min(next, std::max(now, *lastChangeTime_ + config_.minInterval));
  // The command running out.
  auto expiry = commandTime_ + config_.ttl + std::chrono::nanoseconds(1);
  if (command_ && expiry > now) next = std::min(next, expiry);
  return next;
}

CommandPacer::Window CommandPacer::nextWindow(Clock::time_point now) const {
  auto latest = nextDeadline(now);
  if (!lastSent_) return {latest, latest};
  return {std::min(latest, lastSentTime_ + config_.keepalive - config_.keepaliveEarly), latest};
}

void CommandPacer::restart() {
  lastSent_.reset();
  lastChangeTime_.reset();
}

}  // namespace wircam::link
