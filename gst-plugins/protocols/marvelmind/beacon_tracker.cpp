#include "marvelmind/beacon_tracker.h"

namespace wircam::marvelmind {

using std::chrono::milliseconds;

uint64_t ClientStats::rejectedTotal() const {
  uint64_t total = 0;
  for (const auto& [reason, count] : rejected) total += count;
  return total;
}

BeaconTracker::BeaconTracker(const ClientConfig& config, SocketAddress dashboard,
                             uint16_t localPort, Clock::time_point now)
    : config_(config), dashboard_(dashboard), localPort_(localPort), clock_(config.timestampUnit) {
  for (uint8_t address : config_.beacons) beacons_[address].lastNew = now;
}

bool BeaconTracker::fromDashboard(const SocketAddress& from) const {
  if (config_.mode == Mode::kPoll) return from == dashboard_;
  // A pushing dashboard sends from a port of its own choosing.
  return config_.host.empty() || from.sameHost(dashboard_);
}

std::vector<PositionEvent> BeaconTracker::onDatagram(const SocketAddress& from,
                                                     std::span<const uint8_t> datagram,
                                                     Clock::time_point now) {
  if (!fromDashboard(from)) return ++stats_.foreign, std::vector<PositionEvent>{};
  // 256 bytes hold any reply; longer datagrams arrive cut to that and fail
  // the length check.
  auto reply = decodeReply(datagram);
  if (!reply)
    return ++stats_.rejected[decodeErrorName(reply.error())], std::vector<PositionEvent>{};
  auto found = beacons_.find(reply->beacon);
  if (found == beacons_.end())
    return ++stats_.rejected["wrong beacon"], std::vector<PositionEvent>{};
  ++stats_.replies;
  lastReply_ = now;
  Beacon& beacon = found->second;
  if (beacon.lastTimestamp == reply->timestamp)
    return ++stats_.repeats, std::vector<PositionEvent>{};
  beacon.lastTimestamp = reply->timestamp;
  Position position{.beacon = reply->beacon,
                    .x = reply->xMm / 1000.0,
                    .y = reply->yMm / 1000.0,
                    .z = reply->zMm / 1000.0,
                    .timestamp = clock_.seconds(reply->timestamp),
                    .received = now};
  position.measured = clock_.localTime(position.timestamp, now);
  ++stats_.positions;
  beacon.latest = position;
  beacon.lastNew = now;
  beacon.stale = false;
  return {PositionReceived{position}};
}

std::string BeaconTracker::silenceReason(uint8_t beacon, Clock::time_point now) const {
  auto ms = [&](Clock::time_point since) {
    return std::to_string(std::chrono::duration_cast<milliseconds>(now - since).count()) + " ms";
  };
  const Beacon& state = beacons_.at(beacon);
  bool silent = !lastReply_ || now - *lastReply_ >= config_.staleAfter;
  if (silent && config_.mode == Mode::kStream)
    return "nothing pushed by the dashboard to port " + std::to_string(localPort_) + " for " +
           ms(lastReply_.value_or(state.lastNew));
  if (silent)
    return "no reply from the dashboard at " + dashboard_.toString() + " for " +
           ms(lastReply_.value_or(state.lastNew));
  return "the dashboard has no new position of beacon " + std::to_string(beacon) + " for " +
         ms(state.lastNew) + " (out of sight of the stationary beacons, or asleep)";
}

std::optional<Clock::time_point> BeaconTracker::nextDeadline() const {
  std::optional<Clock::time_point> next;
  for (const auto& [address, beacon] : beacons_)
    if (!beacon.stale) {
      auto due = beacon.lastNew + config_.staleAfter;
      if (!next || due < *next) next = due;
    }
  return next;
}

std::vector<PositionEvent> BeaconTracker::onDeadline(Clock::time_point now) {
  std::vector<PositionEvent> events;
  for (auto& [address, beacon] : beacons_)
    if (!beacon.stale && beacon.lastNew + config_.staleAfter <= now) {
      beacon.stale = true;
      events.push_back(PositionStale{address, silenceReason(address, now)});
    }
  return events;
}

std::optional<Position> BeaconTracker::latest(uint8_t beacon) const {
  auto found = beacons_.find(beacon);
  return found == beacons_.end() ? std::nullopt : found->second.latest;
}

}  // namespace wircam::marvelmind
