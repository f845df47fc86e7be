// The WiRC control protocol v1.3: constants and one struct per message, in
// both directions. Frame on the wire (all integers big-endian):
//
//   +------+------+-----+-----+----------------+-----------+
//   | 0xAA | 0xBB | CMD | LEN | body (LEN B)   | CRC16     |
//   +------+------+-----+-----+----------------+-----------+
//                  \____ CRC-16/XMODEM over ____/
//
// encode() refuses values the spec forbids, so no out-of-range pulse or
// period can be put on the wire through it; decode() applies the same rules
// except to text: a peer's text fields are taken up to their first zero byte
// whatever they hold, and made safe to show (UTF-8 kept, other bytes read as
// Latin-1, control characters, C1 included, escaped as \xNN: printableText()).
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <variant>
#include <vector>

#include "common/expected.h"
#include "wirc/protocol_error.h"

namespace wircam::wirc {

constexpr uint8_t kSync1 = 0xAA;
constexpr uint8_t kSync2 = 0xBB;
constexpr size_t kHeaderSize = 4;  // AA BB CMD LEN
constexpr size_t kCrcSize = 2;
constexpr size_t kMaxBodySize = 255;
constexpr size_t kMaxFrameSize = kHeaderSize + kMaxBodySize + kCrcSize;

constexpr uint16_t kDefaultPort = 1984;  // discovery (UDP) and control (TCP)
constexpr size_t kChannelCount = 12;     // ch1..ch8 servo, ch9..ch12 digital
constexpr uint16_t kPulseMin = 800;      // µs, PCD and FCFG range
constexpr uint16_t kPulseMax = 2200;
constexpr uint16_t kPulseNeutral = 1500;
constexpr uint16_t kPeriodMin = 5000;  // µs, CCFG range
constexpr uint16_t kPeriodMax = 20000;
constexpr uint16_t kFailsafeConstantLevel = 0x0000;
constexpr uint16_t kFailsafeHoldLast = 0xFFFF;
constexpr int kPcdTimeoutMs = 800;
constexpr int kPsdPeriodMs = 500;

enum class Command : uint8_t {
  Bcsd = 0x01,
  Bcsa = 0x02,
  Tl = 0x11,
  Dcfg = 0x12,
  Ccfg = 0x13,
  Fcfg = 0x14,
  Wst = 0x1A,
  Pcd = 0x21,
  Psd = 0x22,
  Wcfg = 0x31,
  Tlr = 0x32,
  Tlst = 0x33,
  Tlend = 0x34,
  Areq = 0x35,
  Agr = 0x36,
  Fwup = 0x37,
  Stst = 0x41,
  Est = 0x42,
  Extout = 0x50,
  Err = 0xFF,
};

// ERR codes as the device sends them (protocols/NOTES.md).
enum class ErrorCode : uint16_t {
  None = 0,
  Format = 1,
  Denied = 2,
  System = 3,
  Save = 4,
  Unauthorised = 5,
  Busy = 6,
};

enum class SystemType : uint8_t { PcClient = 0, IPhone = 1, Android = 2 };

struct Version {
  uint8_t major = 0;
  uint8_t minor = 0;
  bool operator==(const Version&) const = default;
};

using ChannelValues = std::array<uint16_t, kChannelCount>;

// Neutral pulses on every channel: what a transmitter sends when it has
// nothing better to say.
constexpr ChannelValues neutralChannels() {
  ChannelValues values{};
  values.fill(kPulseNeutral);
  return values;
}

// Field widths of the fixed-size ASCII strings.
constexpr size_t kNameWidth = 64;
constexpr size_t kSerialWidth = 7;
constexpr size_t kSsidWidth = 32;
constexpr size_t kPasswordWidth = 64;
constexpr size_t kCountryWidth = 3;  // two letters and a zero byte

// Broadcast service discovery, transmitter → device (UDP 1984).
struct Bcsd {
  static constexpr Command kCommand = Command::Bcsd;
  uint8_t system = 0;
  Version version;
  bool operator==(const Bcsd&) const = default;
};

// Broadcast service advertisement, device → transmitter.
struct Bcsa {
  static constexpr Command kCommand = Command::Bcsa;
  Version hardware;
  Version software;
  std::string name;
  std::string serial;
  bool operator==(const Bcsa&) const = default;
};

// Transmitter login, the first message on the TCP connection.
struct Tl {
  static constexpr Command kCommand = Command::Tl;
  uint8_t system = 0;
  Version version;
  uint8_t priority = 0;
  std::string name;
  uint16_t statusPort = 0;  // where the device sends PSD
  bool operator==(const Tl&) const = default;
};

// Device configuration (name); first transmitter only.
struct Dcfg {
  static constexpr Command kCommand = Command::Dcfg;
  std::string name;
  uint16_t cameraOffMillivolts = 0;
  uint16_t deviceOffMillivolts = 0;
  bool operator==(const Dcfg&) const = default;
};

// Channel configuration: pulse repeat period per channel in µs.
struct Ccfg {
  static constexpr Command kCommand = Command::Ccfg;
  ChannelValues periods{};
  bool operator==(const Ccfg&) const = default;
};

// Failsafe configuration: a pulse (800..2200), constant level (0x0000) or
// hold the last PCD value (0xFFFF) per channel.
struct Fcfg {
  static constexpr Command kCommand = Command::Fcfg;
  ChannelValues values{};
  bool operator==(const Fcfg&) const = default;
};

// Device startup: ends the login.
struct Wst {
  static constexpr Command kCommand = Command::Wst;
  uint8_t connectionId = 0;
  uint8_t cameraCount = 0;
  uint16_t controlPort = 0;  // where the transmitter sends PCD
  bool operator==(const Wst&) const = default;
};

// Periodic channel data: pulse width per channel in µs (UDP).
struct Pcd {
  static constexpr Command kCommand = Command::Pcd;
  ChannelValues values{};
  bool operator==(const Pcd&) const = default;
};

// Periodic status data (UDP, every 500 ms).
struct Psd {
  static constexpr Command kCommand = Command::Psd;
  uint16_t batteryMillivolts = 0;
  uint16_t analogMillivolts = 0;
  std::array<uint8_t, 4> inputs{};
  bool operator==(const Psd&) const = default;
};

// WiFi configuration; takes effect after a restart.
struct Wcfg {
  static constexpr Command kCommand = Command::Wcfg;
  std::string ssid;
  std::string password;  // never print or log it
  bool accessPoint = true;
  bool secured = false;
  uint8_t channel = 0;
  std::string country;
  bool operator==(const Wcfg&) const = default;
};

// Transmitter list request.
struct Tlr {
  static constexpr Command kCommand = Command::Tlr;
  bool operator==(const Tlr&) const = default;
};

// One connected transmitter, in answer to TLR.
struct Tlst {
  static constexpr Command kCommand = Command::Tlst;
  uint8_t connectionId = 0;
  uint8_t priority = 0;
  std::string name;
  bool operator==(const Tlst&) const = default;
};

// End of the transmitter list.
struct Tlend {
  static constexpr Command kCommand = Command::Tlend;
  bool operator==(const Tlend&) const = default;
};

// Access request: give the control right to this connection.
struct Areq {
  static constexpr Command kCommand = Command::Areq;
  uint8_t connectionId = 0;
  bool operator==(const Areq&) const = default;
};

enum class AccessNotification : uint8_t {
  Granted = 0,       // the receiver now has the control right
  Denied = 1,        // the receiver's request was refused
  Revoked = 2,       // the receiver lost the control right
  Notification = 3,  // the controller changed (sent to everyone)
};

// Access granted; names the transmitter that holds the control right.
struct Agr {
  static constexpr Command kCommand = Command::Agr;
  uint8_t connectionId = 0;
  uint8_t priority = 0;
  std::string name;
  AccessNotification notification = AccessNotification::Granted;
  bool operator==(const Agr&) const = default;
};

// Firmware update: MD5 of the file uploaded before.
struct Fwup {
  static constexpr Command kCommand = Command::Fwup;
  std::array<uint8_t, 16> md5{};
  bool operator==(const Fwup&) const = default;
};

// Start streaming camera `camera` to UDP `port`.
struct Stst {
  static constexpr Command kCommand = Command::Stst;
  uint8_t camera = 0;
  uint16_t port = 0;
  bool operator==(const Stst&) const = default;
};

// End streaming camera `camera`.
struct Est {
  static constexpr Command kCommand = Command::Est;
  uint8_t camera = 0;
  bool operator==(const Est&) const = default;
};

// Bytes for an external output port of the device.
struct Extout {
  static constexpr Command kCommand = Command::Extout;
  static constexpr size_t kMaxData = 254;
  uint8_t destination = 0;
  std::vector<uint8_t> data;
  bool operator==(const Extout&) const = default;
};

// Error reply: which command failed and why.
struct Err {
  static constexpr Command kCommand = Command::Err;
  uint8_t command = 0;
  uint16_t code = 0;
  bool operator==(const Err&) const = default;
};

using Message = std::variant<Bcsd, Bcsa, Tl, Dcfg, Ccfg, Fcfg, Wst, Pcd, Psd, Wcfg, Tlr, Tlst,
                             Tlend, Areq, Agr, Fwup, Stst, Est, Extout, Err>;

using Bytes = std::vector<uint8_t>;

// The whole frame (AA BB CMD LEN body CRC) of a valid message.
Expected<Bytes, ProtocolError> encode(const Message& message);

// Decodes one whole frame; the input must hold exactly one message.
Expected<Message, ProtocolError> decode(std::span<const uint8_t> frame);

// Decodes a body whose framing and CRC were already checked.
Expected<Message, ProtocolError> decodeBody(uint8_t command, std::span<const uint8_t> body);

// Checks the spec's field rules; nullopt when the message may be sent.
std::optional<ProtocolError> validate(const Message& message);

// Frames an arbitrary body without any checks: for tests and the simulator's
// hostile-sender modes, never for normal sending.
Bytes frameRaw(uint8_t command, std::span<const uint8_t> body);

// "CCFG", "PCD", ... or "0x5A" for codes outside the spec.
std::string commandName(uint8_t command);

uint8_t commandCode(const Message& message);

}  // namespace wircam::wirc
