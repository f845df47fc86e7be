// wirc-cli positions: a Marvelmind beacon's positions from the dashboard,
// one JSON object per line, for scripts.
#pragma once

#include <chrono>
#include <optional>
#include <string>

#include "marvelmind/position_client.h"

namespace wircam::cli {

struct PositionsOptions {
  std::string dashboard;  // HOST:PORT
  std::string beacons;    // "5" or "5,6"
  int count = 10;
  std::chrono::milliseconds timeout{3000};  // without a new position: give up
  double rate = 10;
  std::optional<uint16_t> listenPort;  // stream mode: where the dashboard pushes
  marvelmind::Resolution resolution = marvelmind::Resolution::kCentimetres;
  marvelmind::TimestampUnit timestampUnit = marvelmind::TimestampUnit::kSixtyFourths;
};

// Prints `count` lines {"beacon":5,"x":1.234,"y":-0.5,"z":0.25,"timestamp":12.5}
// (metres; seconds of the dashboard's clock) and returns the exit code.
int printPositions(const PositionsOptions& options);

}  // namespace wircam::cli
