#include "marvelmind/position_client.h"

#include <sys/epoll.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <sstream>

#include "common/mutex.h"
#include "common/socket.h"
#include "link/event_loop.h"

namespace wircam::marvelmind {

using link::EventLoop;
using std::chrono::milliseconds;

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

// The I/O around the BeaconTracker: the socket and timers on the event loop.
class PositionClient::Impl {
 public:
  Impl(ClientConfig config, SocketAddress dashboard, UniqueFd socket, Listener listener,
       EventLoop& loop);
  ~Impl();

  void onReadable();
  void onPollTimer();
  void onStaleTimer();
  void armStaleTimer();

  EventLoop& loop_;
  const ClientConfig config_;
  const SocketAddress dashboard_;
  UniqueFd socket_;
  const Listener listener_;
  const Clock::duration pollPeriod_;
  EventLoop::Id watch_ = 0, pollTimer_ = 0, staleTimer_ = 0;

  mutable Mutex mutex_;  // never held while the listener runs
  BeaconTracker tracker_ WIRCAM_GUARDED_BY(mutex_);
};

PositionClient::Impl::Impl(ClientConfig config, SocketAddress dashboard, UniqueFd socket,
                           Listener listener, EventLoop& loop)
    : loop_(loop),
      config_(std::move(config)),
      dashboard_(dashboard),
      socket_(std::move(socket)),
      listener_(std::move(listener)),
      pollPeriod_(std::chrono::duration_cast<Clock::duration>(
          std::chrono::duration<double>(1.0 / config_.pollRate))),
      tracker_(config_, dashboard_, localAddress(socket_.get()).port(), Clock::now()) {
  watch_ = loop_.watch(socket_.get(), EPOLLIN, [this](uint32_t) { onReadable(); });
  staleTimer_ = loop_.addTimer([this] { onStaleTimer(); });
  armStaleTimer();
  if (config_.mode == Mode::kPoll) {
    pollTimer_ = loop_.addTimer([this] { onPollTimer(); });
    loop_.arm(pollTimer_, Clock::now());
  }
}

PositionClient::Impl::~Impl() {
  loop_.invoke([this] {
    for (auto id : {watch_, pollTimer_, staleTimer_})
      if (id) loop_.remove(id);
  });
}

void PositionClient::Impl::onPollTimer() {
  auto now = Clock::now();
  uint64_t sent = 0;
  for (uint8_t beacon : config_.beacons)
    sent += sendDatagram(socket_.get(), dashboard_,
                         encode(Request{.beacon = beacon, .resolution = config_.resolution}));
  {
    MutexLock lock(mutex_);
    tracker_.countRequests(sent);
  }
  loop_.arm(pollTimer_, now + pollPeriod_);
}

void PositionClient::Impl::onReadable() {
  std::array<uint8_t, 256> buffer;
  std::vector<PositionEvent> events;
  receiveDatagrams(socket_.get(), buffer, 64, [&](auto datagram, const SocketAddress& from) {
    MutexLock lock(mutex_);
    auto caused = tracker_.onDatagram(from, datagram, Clock::now());
    events.insert(events.end(), caused.begin(), caused.end());
  });
  if (!events.empty()) armStaleTimer();
  for (const auto& event : events) listener_(event);
}

void PositionClient::Impl::onStaleTimer() {
  std::vector<PositionEvent> events;
  {
    MutexLock lock(mutex_);
    events = tracker_.onDeadline(Clock::now());
  }
  armStaleTimer();
  for (const auto& event : events) listener_(event);
}

void PositionClient::Impl::armStaleTimer() {
  std::optional<Clock::time_point> deadline;
  {
    MutexLock lock(mutex_);
    deadline = tracker_.nextDeadline();
  }
  if (deadline)
    loop_.arm(staleTimer_, *deadline);
  else
    loop_.disarm(staleTimer_);
}

Expected<std::unique_ptr<PositionClient>, std::string> PositionClient::start(
    const ClientConfig& config, Listener listener, EventLoop& loop) {
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
      std::make_unique<Impl>(config, dashboard, std::move(*socket), std::move(listener), loop);
  return client;
}

PositionClient::~PositionClient() = default;

uint16_t PositionClient::localPort() const { return localAddress(impl_->socket_.get()).port(); }

ClientStats PositionClient::stats() const {
  MutexLock lock(impl_->mutex_);
  return impl_->tracker_.stats();
}

std::optional<Position> PositionClient::latest(uint8_t beacon) const {
  MutexLock lock(impl_->mutex_);
  return impl_->tracker_.latest(beacon);
}

}  // namespace wircam::marvelmind
