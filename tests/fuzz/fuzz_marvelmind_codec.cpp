// Marvelmind datagrams through both decoders, and the same bytes as a
// stream of dashboard timestamps and as a beacon list: what is accepted
// checks its CRC and survives a round trip, no measurement is placed after
// its arrival, and no beacon address outside 1..254 is ever taken.
#include <cstdlib>
#include <string>

#include "marvelmind/dashboard_clock.h"
#include "marvelmind/position_client.h"

using namespace wircam::marvelmind;

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  std::span<const uint8_t> bytes(data, size);
  if (auto reply = decodeReply(bytes)) {
    if (crc16Modbus(bytes) != 0) std::abort();
    auto again = decodeReply(encode(*reply));
    if (!again || !(*again == *reply)) std::abort();
  }
  if (auto request = decodeRequest(bytes)) {
    auto again = decodeRequest(encode(*request));
    if (!again || !(*again == *request)) std::abort();
  }

  DashboardClock clock(size % 2 ? TimestampUnit::kMilliseconds : TimestampUnit::kSixtyFourths);
  auto received = DashboardClock::Clock::time_point(std::chrono::hours(1));
  for (size_t i = 0; i + 4 <= size; i += 4) {
    uint32_t timestamp = uint32_t{data[i]} | uint32_t{data[i + 1]} << 8 |
                         uint32_t{data[i + 2]} << 16 | uint32_t{data[i + 3]} << 24;
    received += std::chrono::milliseconds(data[i] % 50);
    double seconds = clock.seconds(timestamp);
    if (!(seconds >= 0)) std::abort();
    if (clock.localTime(seconds, received) > received) std::abort();
  }

  if (auto beacons = parseBeacons(std::string(reinterpret_cast<const char*>(data), size)))
    for (uint8_t beacon : *beacons)
      if (beacon < 1 || beacon > 254) std::abort();
  return 0;
}
