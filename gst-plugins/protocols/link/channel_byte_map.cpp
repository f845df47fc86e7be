#include "link/channel_byte_map.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <sstream>

namespace wircam::link {

uint8_t ChannelByteMap::toByte(size_t channel, uint16_t pulse) const {
  auto [zero, full] = range(channel);
  double fraction = (static_cast<double>(pulse) - zero) / (static_cast<double>(full) - zero);
  return static_cast<uint8_t>(std::lround(std::clamp(fraction, 0.0, 1.0) * 255));
}

uint16_t ChannelByteMap::toPulse(size_t channel, uint8_t byte) const {
  auto [zero, full] = range(channel);
  return static_cast<uint16_t>(
      std::lround(zero + (static_cast<double>(full) - zero) * byte / 255.0));
}

Expected<ChannelByteMap, std::string> ChannelByteMap::parse(const std::string& text) {
  ChannelByteMap map;
  std::stringstream items(text);
  std::string item;
  while (std::getline(items, item, ',')) {
    unsigned channel = 0, zero = 0, full = 0;
    char end = 0;
    if (std::sscanf(item.c_str(), "%u:%u-%u%c", &channel, &zero, &full, &end) != 3)
      return unexpected("'" + item + "' is not CHANNEL:US-US (e.g. 2:1000-2000)");
    if (channel < 1 || channel > kChannels)
      return unexpected("'" + item + "': channels are 1.." + std::to_string(kChannels));
    if (zero < kPulseMin || zero > kPulseMax || full < kPulseMin || full > kPulseMax ||
        zero == full)
      return unexpected("'" + item + "': both ends within 800..2200 µs, and different");
    map.setRange(channel, {static_cast<uint16_t>(zero), static_cast<uint16_t>(full)});
  }
  return map;
}

std::string ChannelByteMap::toString() const {
  std::string text;
  for (size_t channel = 1; channel <= kChannels; ++channel) {
    if (range(channel) == PulseRange{}) continue;
    if (!text.empty()) text += ",";
    text += std::to_string(channel) + ":" + std::to_string(range(channel).atZero) + "-" +
            std::to_string(range(channel).atFull);
  }
  return text;
}

}  // namespace wircam::link
