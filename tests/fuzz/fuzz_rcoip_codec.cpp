// RCOIP datagrams through both decoders, and channel-map overrides through
// their parser: what is accepted encodes back to the same bytes, and no
// byte maps to a pulse outside 800..2200 µs whatever the overrides.
#include <cstdlib>
#include <string>

#include "link/channel_byte_map.h"
#include "rcoip/rcoip_messages.h"

using namespace wircam;

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  std::span<const uint8_t> bytes(data, size);
  if (auto command = rcoip::decodeCommand(bytes)) {
    if (rcoip::encode(*command) != std::vector<uint8_t>(data, data + size)) std::abort();
  }
  if (auto reply = rcoip::decodeReply(bytes)) {
    if (rcoip::encode(*reply) != std::vector<uint8_t>(data, data + size)) std::abort();
    if (reply->batteryVolts() < 0 || reply->batteryVolts() > 15.0) std::abort();
  }
  auto map = link::ChannelByteMap::parse(std::string(reinterpret_cast<const char*>(data), size));
  if (!map) return 0;
  for (size_t channel = 1; channel <= link::kChannels; ++channel) {
    for (int byte = 0; byte < 256; byte += 15) {
      uint16_t pulse = map->toPulse(channel, static_cast<uint8_t>(byte));
      if (pulse < link::kPulseMin || pulse > link::kPulseMax) std::abort();
    }
  }
  if (auto again = link::ChannelByteMap::parse(map->toString()); !again) std::abort();
  return 0;
}
