#include "marvelmind/position_client.h"

#include <sys/epoll.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <sstream>

#include "common/mutex.h"
#include "common/socket.h"
#include "link/event_loop.h"
#include "marvelmind/dashboard_clock.h"

namespace wircam::marvelmind {

using link::EventLoop;
using std::chrono::milliseconds;

uint64_t ClientStats::rejectedTotal() const {
  uint64_t total = 0;
  for (const auto& [reason, count] : rejected) total += count;
  return total;
}

std::optional<std::string> validate(const ClientConfig& c) {
  if (c.beacons.empty()) return "no beacon address: name the vehicle's beacon(s), as in 5 or 5,6";
  if (c.mode == Mode::kPoll && (c.host.empty() || c.port == 0))
    return "polling needs the dashboard's HOST:PORT";
  if (!std::isfinite(c.pollRate) || c.pollRate < 0.5 || c.pollRate > 100)
    return "poll rate " + std::to_string(c.pollRate) + " Hz: 0.5..100";
  if (c.staleAfter < milliseconds(100)) return "stale-after below 100 ms";
  return std::nullopt;
}

Expected<std::vector<uint8_t>, std::string> parseBeacons(const std::string& text) {
  std::vector<uint8_t> beacons;
  std::stringstream list(text);
  std::string item;
  while (std::getline(list, item, ',')) {
    char* end = nullptr;
    long address = std::strtol(item.c_str(), &end, 10);
    if (item.empty() || *end != '\0' || address < 1 || address > 254)
      return unexpected("beacon '" + item + "' is not an address 1..254");
    if (std::find(beacons.begin(), beacons.end(), address) == beacons.end())
      beacons.push_back(static_cast<uint8_t>(address));
  }
  if (beacons.empty()) return unexpected("no beacon address in '" + text + "'");
  return beacons;
}

class PositionClient::Impl {
 public:
  Impl(ClientConfig config, SocketAddress dashboard, UniqueFd socket, Listener listener);
  ~Impl();

  void onReadable();
  void onPollTimer();
  void onStaleTimer();
  void reject(const std::string& reason) WIRCAM_REQUIRES(mutex_) { ++stats_.rejected[reason]; }
  bool fromDashboard(const SocketAddress& from) const;
  std::string silenceReason(uint8_t beacon, Clock::time_point now) const WIRCAM_REQUIRES(mutex_);

  struct Beacon {
    std::optional<uint32_t> lastTimestamp;  // raw, to tell a repeat from a new measurement
    std::optional<Position> latest;
    Clock::time_point lastNew;  // or the client's start
    bool stale = false;
  };

  const ClientConfig config_;
  const SocketAddress dashboard_;
  UniqueFd socket_;
  const Listener listener_;
  const Clock::duration pollPeriod_;
  EventLoop& loop_ = EventLoop::shared();
  EventLoop::Id watch_ = 0, pollTimer_ = 0, staleTimer_ = 0;

  mutable Mutex mutex_;  // never held while the listener runs
  ClientStats stats_ WIRCAM_GUARDED_BY(mutex_);
  std::map<uint8_t, Beacon> beacons_ WIRCAM_GUARDED_BY(mutex_);
  std::optional<Clock::time_point> lastReply_ WIRCAM_GUARDED_BY(mutex_);
  DashboardClock clock_ WIRCAM_GUARDED_BY(mutex_);
};

PositionClient::Impl::Impl(ClientConfig config, SocketAddress dashboard, UniqueFd socket,
                           Listener listener)
    : config_(std::move(config)),
      dashboard_(dashboard),
      socket_(std::move(socket)),
      listener_(std::move(listener)),
      pollPeriod_(std::chrono::duration_cast<Clock::duration>(
          std::chrono::duration<double>(1.0 / config_.pollRate))),
      clock_(config_.timestampUnit) {
  auto now = Clock::now();
  {
    MutexLock lock(mutex_);
    for (uint8_t address : config_.beacons) beacons_[address].lastNew = now;
  }
  watch_ = loop_.watch(socket_.get(), EPOLLIN, [this](uint32_t) { onReadable(); });
  staleTimer_ = loop_.addTimer([this] { onStaleTimer(); });
  loop_.arm(staleTimer_, now + config_.staleAfter);
  if (config_.mode == Mode::kPoll) {
    pollTimer_ = loop_.addTimer([this] { onPollTimer(); });
    loop_.arm(pollTimer_, now);
  }
}

PositionClient::Impl::~Impl() {
  loop_.invoke([this] {
    for (auto id : {watch_, pollTimer_, staleTimer_})
      if (id) loop_.remove(id);
  });
}

bool PositionClient::Impl::fromDashboard(const SocketAddress& from) const {
  if (config_.mode == Mode::kPoll) return from == dashboard_;
  // A pushing dashboard sends from a port of its own choosing.
  return config_.host.empty() || from.sameHost(dashboard_);
}

void PositionClient::Impl::onPollTimer() {
  // The due time moves on by whole periods, so a late wake does not slow the rate.
  auto now = Clock::now();
  uint64_t sent = 0;
  for (uint8_t beacon : config_.beacons)
    sent += sendDatagram(socket_.get(), dashboard_,
                         encode(Request{.beacon = beacon, .resolution = config_.resolution}));
  {
    MutexLock lock(mutex_);
    stats_.requests += sent;
  }
  loop_.arm(pollTimer_, now + pollPeriod_);
}

void PositionClient::Impl::onReadable() {
  std::array<uint8_t, 256> buffer;
  std::vector<PositionEvent> events;
  receiveDatagrams(socket_.get(), buffer, 64, [&](auto datagram, const SocketAddress& from) {
    auto now = Clock::now();
    MutexLock lock(mutex_);
    if (!fromDashboard(from)) return void(++stats_.foreign);
    // 256 bytes hold any reply; longer datagrams arrive cut to that and
    // fail the length check below.
    auto reply = decodeReply(datagram);
    if (!reply) return reject(decodeErrorName(reply.error()));
    auto found = beacons_.find(reply->beacon);
    if (found == beacons_.end()) return reject("wrong beacon");
    ++stats_.replies;
    lastReply_ = now;
    Beacon& beacon = found->second;
    if (beacon.lastTimestamp == reply->timestamp) return void(++stats_.repeats);
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
    events.push_back(PositionReceived{position});
  });
  for (const auto& event : events) listener_(event);
}

std::string PositionClient::Impl::silenceReason(uint8_t beacon, Clock::time_point now) const {
  auto ms = [&](Clock::time_point since) {
    return std::to_string(std::chrono::duration_cast<milliseconds>(now - since).count()) + " ms";
  };
  const Beacon& state = beacons_.at(beacon);
  bool silent = !lastReply_ || now - *lastReply_ >= config_.staleAfter;
  if (silent && config_.mode == Mode::kStream)
    return "nothing pushed by the dashboard to port " +
           std::to_string(localAddress(socket_.get()).port()) + " for " +
           ms(lastReply_.value_or(state.lastNew));
  if (silent)
    return "no reply from the dashboard at " + dashboard_.toString() + " for " +
           ms(lastReply_.value_or(state.lastNew));
  return "the dashboard has no new position of beacon " + std::to_string(beacon) + " for " +
         ms(state.lastNew) + " (out of sight of the stationary beacons, or asleep)";
}

void PositionClient::Impl::onStaleTimer() {
  auto now = Clock::now();
  std::vector<PositionEvent> events;
  Clock::time_point next = now + config_.staleAfter;
  {
    MutexLock lock(mutex_);
    for (auto& [address, beacon] : beacons_) {
      auto due = beacon.lastNew + config_.staleAfter;
      if (!beacon.stale && due <= now) {
        beacon.stale = true;
        events.push_back(PositionStale{address, silenceReason(address, now)});
      } else if (!beacon.stale) {
        next = std::min(next, due);
      }
    }
  }
  loop_.arm(staleTimer_, next);
  for (const auto& event : events) listener_(event);
}

Expected<std::unique_ptr<PositionClient>, std::string> PositionClient::start(
    const ClientConfig& config, Listener listener) {
  if (auto problem = validate(config)) return unexpected(*problem);
  SocketAddress dashboard;
  if (!config.host.empty()) {
    auto resolved = SocketAddress::resolve(config.host, config.port);
    if (!resolved) return unexpected("dashboard " + config.dashboard() + ": " + resolved.error());
    dashboard = *resolved;
  }
  uint16_t bindPort = config.mode == Mode::kStream ? config.listenPort : 0;
  auto socket = bindUdp(*SocketAddress::resolve("", bindPort));
  if (!socket) return unexpected(socket.error());
  setNonBlocking(socket->get());
  std::unique_ptr<PositionClient> client(new PositionClient());
  client->impl_ =
      std::make_unique<Impl>(config, dashboard, std::move(*socket), std::move(listener));
  return client;
}

PositionClient::~PositionClient() = default;

uint16_t PositionClient::localPort() const { return localAddress(impl_->socket_.get()).port(); }

ClientStats PositionClient::stats() const {
  MutexLock lock(impl_->mutex_);
  return impl_->stats_;
}

std::optional<Position> PositionClient::latest(uint8_t beacon) const {
  MutexLock lock(impl_->mutex_);
  auto found = impl_->beacons_.find(beacon);
  return found == impl_->beacons_.end() ? std::nullopt : found->second.latest;
}

}  // namespace wircam::marvelmind
