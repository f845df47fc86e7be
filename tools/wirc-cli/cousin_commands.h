// wirc-cli's commands for the vehicles that speak RCOIP or BTEMP
// (--protocol rcoip|btemp): drive, info and, for BTEMP, discover.
#pragma once

#include <chrono>
#include <cstdint>
#include <string>

namespace wircam::cli {

struct CousinOptions {
  std::string protocol;  // "rcoip" or "btemp"
  std::string host;      // BTEMP: empty probes the broadcast address
  uint16_t port = 0;     // 0: the protocol's default (9048, 16980)
  std::string broadcastAddress = "255.255.255.255";
  std::chrono::milliseconds timeout{3000};
  int steering = 1500;
  int throttle = 1500;
  double seconds = 1;
};

// Each prints what the vehicle reports and returns the exit code; a
// message on stderr says what went wrong.
int driveCousin(const CousinOptions& options);
int infoCousin(const CousinOptions& options);
int discoverBtemp(const CousinOptions& options);

}  // namespace wircam::cli
