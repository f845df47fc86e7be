// What one option's value means, checked: each reader returns the value or
// says why not (parseControlTarget and parseServerAddress are public, in
// recorder_options.h).
#pragma once

#include <cstdint>
#include <optional>
#include <string>

#include "app/recorder_options.h"

namespace wircam::recorder {

// A finite decimal number, nothing after it.
std::optional<double> number(const char* text);
// A whole number within low..high, or nothing.
std::optional<long long> wholeWithin(const char* text, double low, double high);
// "HOST[:PORT]": the host (maybe empty), and the port if given; nothing if
// the port is not a whole number within lowestPort..65535.
struct HostAndPort {
  std::string host;
  std::optional<uint16_t> port;
};
std::optional<HostAndPort> hostAndPort(const std::string& text, int lowestPort = 1);
// "500M", "20G", "1048576": bytes.
std::optional<uint64_t> byteSize(const char* text);
// "HOST[:PORT][,control=URI]", as --device takes it.
Expected<DeviceTarget, std::string> deviceTarget(const std::string& argument);
// "steering-kp=1.25,max-throttle=0.5" → " steering-kp=1.25 max-throttle=0.5"
// for wirccontrol: the follower's gains and limits, each within the
// element's range (nothing else reaches the pipeline's description).
Expected<std::string, std::string> followTuning(const char* value);
// The dashboard and beacons of a device, both or neither.
Expected<std::optional<PositionSource>, std::string> positionSource(
    const std::optional<std::string>& dashboard, const std::optional<std::string>& beacons);

}  // namespace wircam::recorder
