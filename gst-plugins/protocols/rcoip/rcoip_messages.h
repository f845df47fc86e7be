// RCOIP v1 (Remote Control Over IP, protocols/rcoip.txt): the transmitter
// sends channel bytes, the receiver answers with its status. No length, no
// checksum: the datagram is the message, and the direction tells which.
#pragma once

#include <cstdint>
#include <optional>
#include <span>
#include <vector>

#include "common/expected.h"

namespace wircam::rcoip {

constexpr uint8_t kVersion = 1;
constexpr uint16_t kDefaultReceiverPort = 9048;
constexpr int kReplyIntervalMs = 1000;
constexpr int kFailIntervalMs = 2000;
constexpr int kKeepaliveIntervalMs = 1000;
// The text expects receivers to take at least 100; more is taken for garbage.
constexpr size_t kMaxChannels = 255;

//   +---------+------+------+-----+------+
//   | version | ch0  | ch1  | ... | chN  |   transmitter → receiver
//   +---------+------+------+-----+------+
struct Command {
  std::vector<uint8_t> channels;  // 0 = minimum, 255 = maximum
  bool operator==(const Command&) const = default;
};

//   +---------+------+---------+
//   | version | RSSI | battery |   receiver → transmitter
//   +---------+------+---------+   (a known variant leaves out RSSI)
struct Reply {
  std::optional<uint8_t> rssi;  // arbitrary units; absent in the 2-byte variant
  uint8_t battery = 0;          // 255 = 15.0 V
  double batteryVolts() const { return battery * 15.0 / 255.0; }
  bool operator==(const Reply&) const = default;
};

enum class DecodeError { Empty, WrongVersion, TooLong, WrongLength };
const char* decodeErrorName(DecodeError error);

std::vector<uint8_t> encode(const Command& command);
std::vector<uint8_t> encode(const Reply& reply);
Expected<Command, DecodeError> decodeCommand(std::span<const uint8_t> datagram);
Expected<Reply, DecodeError> decodeReply(std::span<const uint8_t> datagram);

}  // namespace wircam::rcoip
