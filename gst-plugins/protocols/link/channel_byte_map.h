// How a vehicle that takes one byte per channel (RCOIP, BTEMP) reads a
// pulse: 800..2200 µs linearly onto 0..255 (1500 µs → 128), unless a
// channel has a range of its own (a servo with less travel, a reversed one).
#pragma once

#include <array>
#include <cstdint>
#include <string>

#include "common/expected.h"
#include "link/vehicle_link.h"

namespace wircam::link {

// The pulses that byte 0 and byte 255 stand for; min > max reverses.
struct PulseRange {
  uint16_t atZero = kPulseMin;
  uint16_t atFull = kPulseMax;
  bool operator==(const PulseRange&) const = default;
};

class ChannelByteMap {
 public:
  // `channel` counts from 1, as the WiRC channels do.
  void setRange(size_t channel, PulseRange range) { ranges_.at(channel - 1) = range; }
  PulseRange range(size_t channel) const { return ranges_.at(channel - 1); }

  // Pulses outside the range give its nearest end.
  uint8_t toByte(size_t channel, uint16_t pulse) const;
  uint16_t toPulse(size_t channel, uint8_t byte) const;

  // "2:1000-2000,3:2200-800" (channel:pulse at 0-pulse at 255), both ends
  // within 800..2200 µs and different.
  static Expected<ChannelByteMap, std::string> parse(const std::string& text);
  std::string toString() const;  // the overrides, in the form parse() reads

 private:
  std::array<PulseRange, kChannels> ranges_{};
};

}  // namespace wircam::link
