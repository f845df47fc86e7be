#include "positions_command.h"

#include <condition_variable>
#include <cstdio>
#include <deque>
#include <mutex>

namespace wircam::cli {

namespace {

void printLine(const marvelmind::Position& p) {
  std::printf("{\"beacon\":%u,\"x\":%.3f,\"y\":%.3f,\"z\":%.3f,\"timestamp\":%.3f}\n", p.beacon,
              p.x, p.y, p.z, p.timestamp);
  std::fflush(stdout);
}

}  // namespace

int printPositions(const PositionsOptions& o) {
  auto colon = o.dashboard.rfind(':');
  char* end = nullptr;
  long port =
      colon == std::string::npos ? 0 : std::strtol(o.dashboard.c_str() + colon + 1, &end, 10);
  if (colon == std::string::npos || colon == 0 || *end != '\0' || port < 1 || port > 65535) {
    std::fprintf(stderr, "wirc-cli: --marvelmind wants HOST:PORT, not '%s'\n", o.dashboard.c_str());
    return 2;
  }
  auto beacons = marvelmind::parseBeacons(o.beacons);
  if (!beacons) {
    std::fprintf(stderr, "wirc-cli: --beacon: %s\n", beacons.error().c_str());
    return 2;
  }
  marvelmind::ClientConfig config{
      .host = o.dashboard.substr(0, colon),
      .port = static_cast<uint16_t>(port),
      .beacons = *beacons,
      .mode = o.listenPort ? marvelmind::Mode::kStream : marvelmind::Mode::kPoll,
      .listenPort = o.listenPort.value_or(0),
      .pollRate = o.rate,
      .resolution = o.resolution,
      .timestampUnit = o.timestampUnit,
      .staleAfter = o.timeout};

  std::mutex mutex;
  std::condition_variable arrived;
  std::deque<marvelmind::PositionEvent> events;
  auto client = marvelmind::PositionClient::start(config, [&](const auto& event) {
    std::lock_guard lock(mutex);
    events.push_back(event);
    arrived.notify_one();
  });
  if (!client) {
    std::fprintf(stderr, "wirc-cli: %s\n", client.error().c_str());
    return 1;
  }
  int printed = 0;
  std::unique_lock lock(mutex);
  while (printed < o.count) {
    // The client says when a beacon goes stale (after --timeout without a
    // new position); the wait is only a backstop.
    if (!arrived.wait_for(lock, o.timeout * 2, [&] { return !events.empty(); })) break;
    auto event = std::move(events.front());
    events.pop_front();
    if (auto* received = std::get_if<marvelmind::PositionReceived>(&event)) {
      printLine(received->position);
      ++printed;
    } else if (auto* stale = std::get_if<marvelmind::PositionStale>(&event)) {
      std::fprintf(stderr, "wirc-cli: beacon %u: %s\n", stale->beacon, stale->reason.c_str());
      break;
    }
  }
  lock.unlock();
  auto stats = (*client)->stats();
  if (stats.rejectedTotal() + stats.foreign > 0) {
    std::string reasons;
    for (const auto& [reason, count] : stats.rejected)
      reasons += ", " + std::to_string(count) + " " + reason;
    std::fprintf(stderr, "wirc-cli: dropped %llu datagram(s)%s, %llu from elsewhere\n",
                 static_cast<unsigned long long>(stats.rejectedTotal()), reasons.c_str(),
                 static_cast<unsigned long long>(stats.foreign));
  }
  return printed == o.count ? 0 : 1;
}

}  // namespace wircam::cli
