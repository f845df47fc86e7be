#include "wirc/messages.h"

#include <cstdio>
#include <string_view>

#include "common/byte_reader.h"
#include "common/byte_writer.h"
#include "common/printable_text.h"
#include "wirc/crc16.h"

namespace wircam::wirc {

namespace {

struct BodySize {
  size_t min;
  size_t max;
};

// Body length per command, from the spec's LEN column.
template <typename T>
constexpr BodySize kBodySize = {0, 0};
template <>
constexpr BodySize kBodySize<Bcsd> = {3, 3};
template <>
constexpr BodySize kBodySize<Bcsa> = {75, 75};
template <>
constexpr BodySize kBodySize<Tl> = {70, 70};
template <>
constexpr BodySize kBodySize<Dcfg> = {68, 68};
template <>
constexpr BodySize kBodySize<Ccfg> = {24, 24};
template <>
constexpr BodySize kBodySize<Fcfg> = {24, 24};
template <>
constexpr BodySize kBodySize<Wst> = {4, 4};
template <>
constexpr BodySize kBodySize<Pcd> = {24, 24};
template <>
constexpr BodySize kBodySize<Psd> = {8, 8};
template <>
constexpr BodySize kBodySize<Wcfg> = {102, 102};
template <>
constexpr BodySize kBodySize<Tlst> = {66, 66};
template <>
constexpr BodySize kBodySize<Areq> = {1, 1};
template <>
constexpr BodySize kBodySize<Agr> = {67, 67};
template <>
constexpr BodySize kBodySize<Fwup> = {16, 16};
template <>
constexpr BodySize kBodySize<Stst> = {3, 3};
template <>
constexpr BodySize kBodySize<Est> = {1, 1};
template <>
constexpr BodySize kBodySize<Extout> = {1, 255};
template <>
constexpr BodySize kBodySize<Err> = {3, 3};

ProtocolError fieldError(Command command, std::string field, std::string detail) {
  return {ErrorKind::InvalidField, static_cast<uint8_t>(command), std::move(field),
          std::move(detail)};
}

std::string channelField(size_t index, const char* what) {
  return "ch" + std::to_string(index + 1) + " " + what;
}

// Encoding is strict, decoding is not: what wircam sends is printable ASCII,
// while what a peer sends may be any bytes (a phone that logged in as
// "Pál’s iPhone" must still be seen to hold the control right).
enum class TextRule { Strict, Received };

// Text fields are ASCII, fit their field, and hold no zero byte (which would
// end the text early on the receiving side). Received text was made safe to
// show by readText() and is not checked again.
std::optional<ProtocolError> checkText(Command command, const char* field, const std::string& text,
                                       size_t maxLength, TextRule rule) {
  if (rule == TextRule::Received) return std::nullopt;
  if (text.size() > maxLength)
    return fieldError(command, field,
                      std::to_string(text.size()) + " bytes, at most " + std::to_string(maxLength));
  for (unsigned char c : text) {
    if (c < 0x20 || c > 0x7E)
      return fieldError(command, field, "holds a byte outside printable ASCII");
  }
  return std::nullopt;
}

// A text field a peer sent, up to its first zero byte, made safe to show.
std::string readText(ByteReader& r, size_t width) {
  return printableText(r.readFixedString(width));
}

void writeVersion(ByteWriter& w, Version v) {
  w.writeU8(v.major);
  w.writeU8(v.minor);
}

Version readVersion(ByteReader& r) {
  Version v;
  v.major = r.readU8();
  v.minor = r.readU8();
  return v;
}

void writeChannels(ByteWriter& w, const ChannelValues& values) {
  for (uint16_t v : values) w.writeU16Be(v);
}

ChannelValues readChannels(ByteReader& r) {
  ChannelValues values{};
  for (auto& v : values) v = r.readU16Be();
  return values;
}

// --- encodeBody / readBody / check, one set per message -------------------

void encodeBody(const Bcsd& m, ByteWriter& w) {
  w.writeU8(m.system);
  writeVersion(w, m.version);
}
void readBody(ByteReader& r, Bcsd& m) {
  m.system = r.readU8();
  m.version = readVersion(r);
}
std::optional<ProtocolError> check(const Bcsd&) { return std::nullopt; }

void encodeBody(const Bcsa& m, ByteWriter& w) {
  writeVersion(w, m.hardware);
  writeVersion(w, m.software);
  w.writeFixedString(m.name, kNameWidth);
  w.writeFixedString(m.serial, kSerialWidth);
}
void readBody(ByteReader& r, Bcsa& m) {
  m.hardware = readVersion(r);
  m.software = readVersion(r);
  m.name = readText(r, kNameWidth);
  m.serial = readText(r, kSerialWidth);
}
std::optional<ProtocolError> check(const Bcsa& m, TextRule rule = TextRule::Strict) {
  if (auto e = checkText(Command::Bcsa, "name", m.name, kNameWidth, rule)) return e;
  return checkText(Command::Bcsa, "serial", m.serial, kSerialWidth, rule);
}

void encodeBody(const Tl& m, ByteWriter& w) {
  w.writeU8(m.system);
  writeVersion(w, m.version);
  w.writeU8(m.priority);
  w.writeFixedString(m.name, kNameWidth);
  w.writeU16Be(m.statusPort);
}
void readBody(ByteReader& r, Tl& m) {
  m.system = r.readU8();
  m.version = readVersion(r);
  m.priority = r.readU8();
  m.name = readText(r, kNameWidth);
  m.statusPort = r.readU16Be();
}
std::optional<ProtocolError> check(const Tl& m, TextRule rule = TextRule::Strict) {
  return checkText(Command::Tl, "name", m.name, kNameWidth, rule);
}

void encodeBody(const Dcfg& m, ByteWriter& w) {
  w.writeFixedString(m.name, kNameWidth);
  w.writeU16Be(m.cameraOffMillivolts);
  w.writeU16Be(m.deviceOffMillivolts);
}
void readBody(ByteReader& r, Dcfg& m) {
  m.name = readText(r, kNameWidth);
  m.cameraOffMillivolts = r.readU16Be();
  m.deviceOffMillivolts = r.readU16Be();
}
std::optional<ProtocolError> check(const Dcfg& m, TextRule rule = TextRule::Strict) {
  return checkText(Command::Dcfg, "name", m.name, kNameWidth, rule);
}

void encodeBody(const Ccfg& m, ByteWriter& w) { writeChannels(w, m.periods); }
void readBody(ByteReader& r, Ccfg& m) { m.periods = readChannels(r); }
std::optional<ProtocolError> check(const Ccfg& m) {
  // ch7/ch8 are fixed at 20 ms and ch9..ch12 are digital: their fields are
  // not used, so only ch1..ch6 are checked.
  for (size_t i = 0; i < 6; ++i) {
    uint16_t period = m.periods[i];
    if (period < kPeriodMin || period > kPeriodMax)
      return fieldError(Command::Ccfg, channelField(i, "period"),
                        std::to_string(period) + " µs is outside 5000..20000");
  }
  for (size_t i = 0; i < 6; i += 2) {
    if (m.periods[i] != m.periods[i + 1])
      return fieldError(Command::Ccfg, channelField(i + 1, "period"),
                        "ch" + std::to_string(i + 1) + " and ch" + std::to_string(i + 2) +
                            " must have the same period (" + std::to_string(m.periods[i]) + " vs " +
                            std::to_string(m.periods[i + 1]) + " µs)");
  }
  return std::nullopt;
}

bool isPulse(uint16_t v) { return v >= kPulseMin && v <= kPulseMax; }

void encodeBody(const Fcfg& m, ByteWriter& w) { writeChannels(w, m.values); }
void readBody(ByteReader& r, Fcfg& m) { m.values = readChannels(r); }
std::optional<ProtocolError> check(const Fcfg& m) {
  for (size_t i = 0; i < kChannelCount; ++i) {
    uint16_t v = m.values[i];
    if (!isPulse(v) && v != kFailsafeConstantLevel && v != kFailsafeHoldLast)
      return fieldError(Command::Fcfg, channelField(i, "failsafe"),
                        std::to_string(v) + " is neither 800..2200 µs nor 0x0000/0xFFFF");
  }
  return std::nullopt;
}

void encodeBody(const Wst& m, ByteWriter& w) {
  w.writeU8(m.connectionId);
  w.writeU8(m.cameraCount);
  w.writeU16Be(m.controlPort);
}
void readBody(ByteReader& r, Wst& m) {
  m.connectionId = r.readU8();
  m.cameraCount = r.readU8();
  m.controlPort = r.readU16Be();
}
std::optional<ProtocolError> check(const Wst&) { return std::nullopt; }

void encodeBody(const Pcd& m, ByteWriter& w) { writeChannels(w, m.values); }
void readBody(ByteReader& r, Pcd& m) { m.values = readChannels(r); }
std::optional<ProtocolError> check(const Pcd& m) {
  for (size_t i = 0; i < kChannelCount; ++i) {
    if (!isPulse(m.values[i]))
      return fieldError(Command::Pcd, channelField(i, "value"),
                        std::to_string(m.values[i]) + " µs is outside 800..2200");
  }
  return std::nullopt;
}

void encodeBody(const Psd& m, ByteWriter& w) {
  w.writeU16Be(m.batteryMillivolts);
  w.writeU16Be(m.analogMillivolts);
  for (uint8_t in : m.inputs) w.writeU8(in);
}
void readBody(ByteReader& r, Psd& m) {
  m.batteryMillivolts = r.readU16Be();
  m.analogMillivolts = r.readU16Be();
  for (auto& in : m.inputs) in = r.readU8();
}
std::optional<ProtocolError> check(const Psd&) { return std::nullopt; }

void encodeBody(const Wcfg& m, ByteWriter& w) {
  w.writeFixedString(m.ssid, kSsidWidth);
  w.writeFixedString(m.password, kPasswordWidth);
  w.writeU8(m.accessPoint ? 1 : 0);
  w.writeU8(m.secured ? 1 : 0);
  w.writeU8(m.channel);
  w.writeFixedString(m.country, kCountryWidth);
}
void readBody(ByteReader& r, Wcfg& m) {
  m.ssid = readText(r, kSsidWidth);
  m.password = readText(r, kPasswordWidth);
  // AP and Sec are 0/1 on the wire; any non-zero byte is taken as 1.
  m.accessPoint = r.readU8() != 0;
  m.secured = r.readU8() != 0;
  m.channel = r.readU8();
  m.country = readText(r, kCountryWidth);
}
std::optional<ProtocolError> check(const Wcfg& m, TextRule rule = TextRule::Strict) {
  if (auto e = checkText(Command::Wcfg, "ssid", m.ssid, kSsidWidth, rule)) return e;
  if (auto e = checkText(Command::Wcfg, "password", m.password, kPasswordWidth, rule)) return e;
  return checkText(Command::Wcfg, "country", m.country, kCountryWidth - 1, rule);
}

void encodeBody(const Tlr&, ByteWriter&) {}
void readBody(ByteReader&, Tlr&) {}
std::optional<ProtocolError> check(const Tlr&) { return std::nullopt; }

void encodeBody(const Tlst& m, ByteWriter& w) {
  w.writeU8(m.connectionId);
  w.writeU8(m.priority);
  w.writeFixedString(m.name, kNameWidth);
}
void readBody(ByteReader& r, Tlst& m) {
  m.connectionId = r.readU8();
  m.priority = r.readU8();
  m.name = readText(r, kNameWidth);
}
std::optional<ProtocolError> check(const Tlst& m, TextRule rule = TextRule::Strict) {
  return checkText(Command::Tlst, "name", m.name, kNameWidth, rule);
}

void encodeBody(const Tlend&, ByteWriter&) {}
void readBody(ByteReader&, Tlend&) {}
std::optional<ProtocolError> check(const Tlend&) { return std::nullopt; }

void encodeBody(const Areq& m, ByteWriter& w) { w.writeU8(m.connectionId); }
void readBody(ByteReader& r, Areq& m) { m.connectionId = r.readU8(); }
std::optional<ProtocolError> check(const Areq&) { return std::nullopt; }

void encodeBody(const Agr& m, ByteWriter& w) {
  w.writeU8(m.connectionId);
  w.writeU8(m.priority);
  w.writeFixedString(m.name, kNameWidth);
  w.writeU8(static_cast<uint8_t>(m.notification));
}
void readBody(ByteReader& r, Agr& m) {
  m.connectionId = r.readU8();
  m.priority = r.readU8();
  m.name = readText(r, kNameWidth);
  m.notification = static_cast<AccessNotification>(r.readU8());
}
std::optional<ProtocolError> check(const Agr& m, TextRule rule = TextRule::Strict) {
  if (static_cast<uint8_t>(m.notification) > 3)
    return fieldError(Command::Agr, "notif",
                      std::to_string(static_cast<int>(m.notification)) + " is not 0..3");
  return checkText(Command::Agr, "name", m.name, kNameWidth, rule);
}

void encodeBody(const Fwup& m, ByteWriter& w) { w.writeBytes(m.md5); }
void readBody(ByteReader& r, Fwup& m) {
  auto bytes = r.readBytes(m.md5.size());
  std::copy(bytes.begin(), bytes.end(), m.md5.begin());
}
std::optional<ProtocolError> check(const Fwup&) { return std::nullopt; }

void encodeBody(const Stst& m, ByteWriter& w) {
  w.writeU8(m.camera);
  w.writeU16Be(m.port);
}
void readBody(ByteReader& r, Stst& m) {
  m.camera = r.readU8();
  m.port = r.readU16Be();
}
std::optional<ProtocolError> check(const Stst&) { return std::nullopt; }

void encodeBody(const Est& m, ByteWriter& w) { w.writeU8(m.camera); }
void readBody(ByteReader& r, Est& m) { m.camera = r.readU8(); }
std::optional<ProtocolError> check(const Est&) { return std::nullopt; }

void encodeBody(const Extout& m, ByteWriter& w) {
  w.writeU8(m.destination);
  w.writeBytes(m.data);
}
void readBody(ByteReader& r, Extout& m) {
  m.destination = r.readU8();
  auto rest = r.readRest();
  m.data.assign(rest.begin(), rest.end());
}
std::optional<ProtocolError> check(const Extout& m) {
  if (m.data.size() > Extout::kMaxData)
    return fieldError(Command::Extout, "data",
                      std::to_string(m.data.size()) + " bytes, at most 254");
  return std::nullopt;
}

void encodeBody(const Err& m, ByteWriter& w) {
  w.writeU8(m.command);
  w.writeU16Be(m.code);
}
void readBody(ByteReader& r, Err& m) {
  m.command = r.readU8();
  m.code = r.readU16Be();
}
std::optional<ProtocolError> check(const Err&) { return std::nullopt; }

// Decodes the body as the message type whose command code matches, trying
// each alternative of Message in turn.
template <size_t I = 0>
Expected<Message, ProtocolError> decodeAs(uint8_t command, std::span<const uint8_t> body) {
  if constexpr (I == std::variant_size_v<Message>) {
    return unexpected(ProtocolError{ErrorKind::UnknownCommand, command, "",
                                    "unknown command " + commandName(command)});
  } else {
    using T = std::variant_alternative_t<I, Message>;
    if (static_cast<uint8_t>(T::kCommand) != command) return decodeAs<I + 1>(command, body);
    constexpr BodySize size = kBodySize<T>;
    if (body.size() < size.min || body.size() > size.max) {
      std::string expected = size.min == size.max
                                 ? std::to_string(size.min)
                                 : std::to_string(size.min) + ".." + std::to_string(size.max);
      return unexpected(
          ProtocolError{ErrorKind::BadLength, command, "LEN",
                        "body is " + std::to_string(body.size()) + " bytes, expected " + expected});
    }
    T message;
    ByteReader reader(body);
    readBody(reader, message);
    std::optional<ProtocolError> error;
    if constexpr (requires { check(message, TextRule::Received); })
      error = check(message, TextRule::Received);
    else
      error = check(message);
    if (error) return unexpected(std::move(*error));
    return Message{std::move(message)};
  }
}

}  // namespace

std::string ProtocolError::message() const {
  std::string text = commandName(command);
  if (!field.empty()) text += " " + field;
  return text + ": " + detail;
}

const char* errorKindName(ErrorKind kind) {
  switch (kind) {
    case ErrorKind::BadCrc:
      return "bad-crc";
    case ErrorKind::UnknownCommand:
      return "unknown-command";
    case ErrorKind::BadLength:
      return "bad-length";
    case ErrorKind::InvalidField:
      return "invalid-field";
  }
  return "unknown";
}

std::optional<ProtocolError> validate(const Message& message) {
  return std::visit([](const auto& m) { return check(m); }, message);
}

uint8_t commandCode(const Message& message) {
  return std::visit([](const auto& m) { return static_cast<uint8_t>(m.kCommand); }, message);
}

Bytes frameRaw(uint8_t command, std::span<const uint8_t> body) {
  Bytes frame;
  frame.reserve(kHeaderSize + body.size() + kCrcSize);
  ByteWriter w(frame);
  w.writeU8(kSync1);
  w.writeU8(kSync2);
  w.writeU8(command);
  w.writeU8(static_cast<uint8_t>(body.size()));
  w.writeBytes(body);
  w.writeU16Be(crc16Xmodem(std::span(frame).subspan(2)));
  return frame;
}

Expected<Bytes, ProtocolError> encode(const Message& message) {
  if (auto error = validate(message)) return unexpected(std::move(*error));
  Bytes body;
  ByteWriter writer(body);
  std::visit([&](const auto& m) { encodeBody(m, writer); }, message);
  return frameRaw(commandCode(message), body);
}

Expected<Message, ProtocolError> decodeBody(uint8_t command, std::span<const uint8_t> body) {
  return decodeAs(command, body);
}

Expected<Message, ProtocolError> decode(std::span<const uint8_t> frame) {
  ByteReader reader(frame);
  uint8_t sync1 = reader.readU8();
  uint8_t sync2 = reader.readU8();
  uint8_t command = reader.readU8();
  uint8_t length = reader.readU8();
  auto body = reader.readBytes(length);
  uint16_t crc = reader.readU16Be();
  if (!reader.ok() || reader.remaining() != 0)
    return unexpected(ProtocolError{ErrorKind::BadLength, command, "LEN",
                                    "frame is " + std::to_string(frame.size()) +
                                        " bytes, LEN says " +
                                        std::to_string(length + kHeaderSize + kCrcSize)});
  if (sync1 != kSync1 || sync2 != kSync2)
    return unexpected(
        ProtocolError{ErrorKind::BadLength, command, "frame", "does not start with AA BB"});
  uint16_t computed = crc16Xmodem(frame.subspan(2, kHeaderSize - 2 + length));
  if (crc != computed)
    return unexpected(ProtocolError{ErrorKind::BadCrc, command, "CRC", "checksum mismatch"});
  return decodeBody(command, body);
}

std::string commandName(uint8_t command) {
  switch (static_cast<Command>(command)) {
    case Command::Bcsd:
      return "BCSD";
    case Command::Bcsa:
      return "BCSA";
    case Command::Tl:
      return "TL";
    case Command::Dcfg:
      return "DCFG";
    case Command::Ccfg:
      return "CCFG";
    case Command::Fcfg:
      return "FCFG";
    case Command::Wst:
      return "WST";
    case Command::Pcd:
      return "PCD";
    case Command::Psd:
      return "PSD";
    case Command::Wcfg:
      return "WCFG";
    case Command::Tlr:
      return "TLR";
    case Command::Tlst:
      return "TLST";
    case Command::Tlend:
      return "TLEND";
    case Command::Areq:
      return "AREQ";
    case Command::Agr:
      return "AGR";
    case Command::Fwup:
      return "FWUP";
    case Command::Stst:
      return "STST";
    case Command::Est:
      return "EST";
    case Command::Extout:
      return "EXTOUT";
    case Command::Err:
      return "ERR";
  }
  char text[8];
  std::snprintf(text, sizeof text, "0x%02X", command);
  return text;
}

}  // namespace wircam::wirc
