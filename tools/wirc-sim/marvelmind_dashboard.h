// A simulated Marvelmind dashboard (wirc-sim --marvelmind): it measures its
// mobile beacons' true positions at `rate`, with Gaussian noise and missed
// measurements, answers requests for them (cm or mm, as asked) and, when
// told where, pushes every new measurement there as the stream mode does.
// The first beacon rides on the car, the second on the target, any others
// stand still.
#pragma once

#include <array>
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "common/expected.h"
#include "common/socket.h"
#include "marvelmind/marvelmind_messages.h"

namespace wircam::sim {

struct DashboardConfig {
  std::string bindAddress = "127.0.0.1";
  uint16_t port = 0;  // 0: a free one
  std::vector<uint8_t> beacons = {5};
  double rate = 16;     // measurements per second
  double noise = 0.02;  // m, standard deviation per axis
  double dropout = 0;   // probability a measurement is missed
  marvelmind::TimestampUnit timestampUnit = marvelmind::TimestampUnit::kSixtyFourths;
  std::optional<SocketAddress> pushTo;  // stream mode
  marvelmind::Resolution pushResolution = marvelmind::Resolution::kCentimetres;
  uint32_t seed = 1;
};

struct DashboardStats {
  uint64_t measurements = 0;
  uint64_t missed = 0;  // dropouts
  uint64_t requests = 0;
  uint64_t replies = 0;
  uint64_t pushed = 0;
  uint64_t badRequests = 0;  // malformed, or for a beacon it does not know
};

class MarvelmindDashboard {
 public:
  // Where beacon number `index` (of config.beacons) truly is: x, y, z in m.
  using TruthSource = std::function<std::array<double, 3>(size_t index)>;

  static Expected<std::unique_ptr<MarvelmindDashboard>, std::string> start(DashboardConfig config,
                                                                           TruthSource truth);
  ~MarvelmindDashboard();
  MarvelmindDashboard(const MarvelmindDashboard&) = delete;
  MarvelmindDashboard& operator=(const MarvelmindDashboard&) = delete;

  uint16_t port() const;
  DashboardStats stats() const;
  std::string summary() const;  // one line of counters

  class Impl;

 private:
  MarvelmindDashboard() = default;
  std::unique_ptr<Impl> impl_;
};

}  // namespace wircam::sim
