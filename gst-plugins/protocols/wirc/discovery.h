// Finding WiRC devices: broadcast BCSD, collect the BCSA answers.
#pragma once

#include <chrono>
#include <optional>
#include <string>
#include <vector>

#include "common/expected.h"
#include "common/socket.h"
#include "wirc/messages.h"

namespace wircam::wirc {

struct DiscoveredDevice {
  SocketAddress address;  // where the BCSA came from: the device's control address
  Bcsa advertisement;
};

// Sends BCSD to `target` (by default the broadcast address on port 1984) and
// collects distinct answers until `timeout`.
Expected<std::vector<DiscoveredDevice>, std::string> discoverDevices(
    std::chrono::milliseconds timeout, const std::string& target = "255.255.255.255",
    uint16_t port = kDefaultPort);

// The two halves of discoverDevices(), for callers that wait on their own
// event loop: a bound socket that has sent BCSD to `destination`, and one
// answer read from it (nothing when the datagram is not a BCSA).
Expected<UniqueFd, std::string> sendDiscoveryRequest(const SocketAddress& destination);
std::optional<DiscoveredDevice> readDiscoveryAnswer(int fd);

// The device whose name or serial is `wanted`, or the only one when `wanted`
// is empty; an error names what was found otherwise.
Expected<DiscoveredDevice, std::string> pickDevice(const std::vector<DiscoveredDevice>& found,
                                                   const std::string& wanted);

}  // namespace wircam::wirc
