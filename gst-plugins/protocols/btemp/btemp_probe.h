// Finding BTEMP robots: a PING to a named host and port, or to every
// broadcast port the author's nodes may bind (16980..17079).
#pragma once

#include <chrono>
#include <string>
#include <vector>

#include "btemp/btemp_messages.h"
#include "common/expected.h"
#include "common/socket.h"

namespace wircam::btemp {

// Sends one round of probes from `fd` (which must allow broadcast). An
// empty host probes `broadcastAddress` on every port of the range.
Expected<std::monostate, std::string> sendProbes(int fd, const std::string& host, uint16_t port,
                                                 const std::string& broadcastAddress,
                                                 const Ping& ping);

struct FoundRobot {
  SocketAddress address;
  NodeInfo node;
};
// Probes once a second until `timeout`; every robot that answered.
Expected<std::vector<FoundRobot>, std::string> discoverRobots(std::chrono::milliseconds timeout,
                                                              const std::string& host,
                                                              uint16_t port,
                                                              const std::string& broadcastAddress);

// A UDP socket on any port, non-blocking, allowed to broadcast.
Expected<UniqueFd, std::string> openBroadcastSocket();

}  // namespace wircam::btemp
