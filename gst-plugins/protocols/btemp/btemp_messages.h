// BTEMP, the robot-control protocol of the BTIC CTLV family
// (protocols/btemp.txt, with the framing from protocols/NOTES.md): UDP
// datagrams of a hashed sync header and TLVs, each message an E4 TLV named
// by a FOURCC. Integers are big-endian; a GUID is 16 raw bytes.
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <variant>
#include <vector>

#include "common/expected.h"

namespace wircam::btemp {

constexpr uint16_t kDefaultPort = 16980;
constexpr uint16_t kControllerPort = 16990;  // the author's controller binds this first
constexpr uint16_t kProbePortFirst = 16980;  // discovery probes this range
constexpr uint16_t kProbePortLast = 17079;
constexpr int kCtrlPeriodMs = 100;
constexpr int kKeepaliveTimeoutMs = 10000;

using Guid = std::array<uint8_t, 16>;
std::string formatGuid(const Guid& guid);  // 32 hex digits

// Node flags: the low 5 bits say what a node is; bits 6..7 whether a PING
// wants an answer.
enum class NodeType : uint8_t { Unknown = 0, Controller = 1, Robot = 2 };
constexpr uint32_t kNoResponse = 1u << 6;  // PING only: do not answer
constexpr uint32_t nodeFlags(NodeType type) { return static_cast<uint32_t>(type); }
constexpr NodeType nodeTypeOf(uint32_t flags) { return static_cast<NodeType>(flags & 0x1F); }
constexpr bool wantsResponse(uint32_t flags) { return ((flags >> 6) & 3) == 0; }
const char* nodeTypeName(NodeType type);

struct NodeInfo {
  Guid node{};
  uint32_t flags = 0;
  bool operator==(const NodeInfo&) const = default;
};

struct Ping {
  std::optional<NodeInfo> sender;  // optional: a bare PING probes for hosts
  bool operator==(const Ping&) const = default;
};
struct Piak {
  NodeInfo node;
  bool operator==(const Piak&) const = default;
};
// Register Controller: auth tag 0 = none, format tag 0 = the CTRL below.
struct Rctr {
  Guid node{};
  Guid auth{};
  uint16_t authTag = 0;
  uint16_t formatTag = 0;
  bool operator==(const Rctr&) const = default;
};
struct Rcak {
  bool operator==(const Rcak&) const = default;
};
struct Ctrl {
  uint32_t impulse1 = 0;  // bits 0..9 keypad digits, 10..13 up/down/left/right
  uint32_t impulse2 = 0;
  std::array<uint8_t, 4> throttle{};  // Throt1..Throt4
  bool operator==(const Ctrl&) const = default;
};
struct Idle {
  bool operator==(const Idle&) const = default;
};
struct Pins {
  uint32_t inputs = 0;        // InMask: inputs that are set
  uint32_t outputs = 0;       // OutMask: outputs that are set
  uint32_t pdmMask = 0;       // outputs able to do PDM/PWM
  uint32_t pdmActive = 0;     // of those, the ones doing it now
  std::vector<uint8_t> duty;  // one per bit of pdmMask, lowest pin first
  bool operator==(const Pins&) const = default;
};
// VS1G/VZ1G/VS1H: recognised, never decoded (the block codecs are not public).
struct VideoSegment {
  std::string fourcc;
  bool operator==(const VideoSegment&) const = default;
};
using Message = std::variant<Ping, Piak, Rctr, Rcak, Ctrl, Idle, Pins, VideoSegment>;
std::string messageName(const Message& message);

enum class DecodeError {
  TooShort,        // not even a sync header and one TLV header
  BadSync,         // the first byte is not EF
  BadHash,         // the sync hash does not match the bytes it covers
  UnknownTlv,      // a TLV tag other than E3/E4/E5 first
  BadTlvLength,    // a TLV length beyond the datagram or below its header
  UnknownMessage,  // a FOURCC/TWOCC this protocol does not have
  BadBody,         // a known message with the wrong body size
};
const char* decodeErrorName(DecodeError error);

//   +----+----+----+----+----+-----------+---------+----------+
//   | EF | h2 | h1 | h0 | E4 | length:24 | FOURCC  | body ... |
//   +----+----+----+----+----+-----------+---------+----------+
//   h: 24-bit hash of the first N bytes with h2 h1 h0 read as 'B' 'T' 'E'
//   (N = 12 after E4, 10 after E3, 8 after E5); length counts from the tag.
// The hash of `covered`, the first N bytes of a datagram.
uint32_t syncHash(std::span<const uint8_t> covered);

std::vector<uint8_t> encode(const Message& message);
Expected<Message, DecodeError> decode(std::span<const uint8_t> datagram);

}  // namespace wircam::btemp
