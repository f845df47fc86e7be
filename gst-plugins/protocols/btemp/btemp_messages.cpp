#include "btemp/btemp_messages.h"

#include <bit>
#include <cstdio>

#include "common/byte_reader.h"
#include "common/byte_writer.h"

namespace wircam::btemp {

namespace {

constexpr uint8_t kSync = 0xEF;
constexpr uint8_t kTlvTwoccLong = 0xE3;   // len:u24 + TWOCC
constexpr uint8_t kTlvFourcc = 0xE4;      // len:u24 + FOURCC
constexpr uint8_t kTlvTwoccShort = 0xE5;  // len:u8 + TWOCC
constexpr size_t kSyncSize = 4;

// How many bytes the hash covers after a first TLV of this tag.
size_t hashedSize(uint8_t tag) {
  switch (tag) {
    case kTlvTwoccLong:
      return 10;
    case kTlvFourcc:
      return 12;
    case kTlvTwoccShort:
      return 8;
  }
  return 0;
}

void writeGuid(ByteWriter& writer, const Guid& guid) { writer.writeBytes(guid); }

Guid readGuid(ByteReader& reader) {
  Guid guid{};
  auto bytes = reader.readBytes(guid.size());
  std::copy(bytes.begin(), bytes.end(), guid.begin());
  return guid;
}

struct Body {
  std::string fourcc;
  std::vector<uint8_t> bytes;
};

Body bodyOf(const Message& message) {
  Body body;
  ByteWriter w(body.bytes);
  struct Writer {
    Body& body;
    ByteWriter& w;
    void operator()(const Ping& m) {
      body.fourcc = "PING";
      if (m.sender) {
        writeGuid(w, m.sender->node);
        w.writeU32Be(m.sender->flags);
      }
    }
    void operator()(const Piak& m) {
      body.fourcc = "PIAK";
      writeGuid(w, m.node.node);
      w.writeU32Be(m.node.flags);
    }
    void operator()(const Rctr& m) {
      body.fourcc = "RCTR";
      writeGuid(w, m.node);
      writeGuid(w, m.auth);
      w.writeU16Be(m.authTag);
      w.writeU16Be(m.formatTag);
    }
    void operator()(const Rcak&) { body.fourcc = "RCAK"; }
    void operator()(const Ctrl& m) {
      body.fourcc = "CTRL";
      w.writeU32Be(m.impulse1);
      w.writeU32Be(m.impulse2);
      w.writeBytes(m.throttle);
    }
    void operator()(const Idle&) { body.fourcc = "IDLE"; }
    void operator()(const Pins& m) {
      body.fourcc = "PINS";
      w.writeU32Be(m.inputs);
      w.writeU32Be(m.outputs);
      w.writeU32Be(m.pdmMask);
      w.writeU32Be(m.pdmActive);
      // Exactly one duty byte per PDM pin, whatever the vector holds.
      for (int i = 0; i < std::popcount(m.pdmMask); ++i)
        w.writeU8(i < static_cast<int>(m.duty.size()) ? m.duty[i] : 0);
    }
    void operator()(const VideoSegment& m) { body.fourcc = (m.fourcc + "????").substr(0, 4); }
  };
  std::visit(Writer{body, w}, message);
  return body;
}

Expected<Message, DecodeError> decodeBody(const std::string& fourcc, ByteReader& r) {
  auto exact = [&](auto message) -> Expected<Message, DecodeError> {
    if (!r.ok() || r.remaining() != 0) return unexpected(DecodeError::BadBody);
    return Message{std::move(message)};
  };
  if (fourcc == "PING") {
    if (r.remaining() == 0) return Message{Ping{}};
    NodeInfo sender{readGuid(r), r.readU32Be()};
    return exact(Ping{sender});
  }
  if (fourcc == "PIAK") return exact(Piak{{readGuid(r), r.readU32Be()}});
  if (fourcc == "RCTR") {
    Rctr m;
    m.node = readGuid(r);
    m.auth = readGuid(r);
    m.authTag = r.readU16Be();
    m.formatTag = r.readU16Be();
    return exact(m);
  }
  if (fourcc == "RCAK") return exact(Rcak{});
  if (fourcc == "IDLE") return exact(Idle{});
  if (fourcc == "CTRL") {
    Ctrl m;
    m.impulse1 = r.readU32Be();
    m.impulse2 = r.readU32Be();
    auto throttle = r.readBytes(4);
    std::copy(throttle.begin(), throttle.end(), m.throttle.begin());
    return exact(m);
  }
  if (fourcc == "PINS") {
    Pins m;
    m.inputs = r.readU32Be();
    m.outputs = r.readU32Be();
    m.pdmMask = r.readU32Be();
    m.pdmActive = r.readU32Be();
    auto duty = r.readBytes(static_cast<size_t>(std::popcount(m.pdmMask)));
    m.duty.assign(duty.begin(), duty.end());
    return exact(m);
  }
  if (fourcc == "VS1G" || fourcc == "VZ1G" || fourcc == "VS1H") {
    r.readRest();  // opaque: their block codecs are not public
    return Message{VideoSegment{fourcc}};
  }
  return unexpected(DecodeError::UnknownMessage);
}

}  // namespace

std::string formatGuid(const Guid& guid) {
  std::string text;
  char digits[3];
  for (uint8_t byte : guid) {
    std::snprintf(digits, sizeof digits, "%02x", byte);
    text += digits;
  }
  return text;
}

const char* nodeTypeName(NodeType type) {
  switch (type) {
    case NodeType::Unknown:
      return "unknown";
    case NodeType::Controller:
      return "controller";
    case NodeType::Robot:
      return "robot";
  }
  return "reserved";
}

std::string messageName(const Message& message) {
  if (const auto* video = std::get_if<VideoSegment>(&message)) return video->fourcc;
  return bodyOf(message).fourcc;
}

const char* decodeErrorName(DecodeError error) {
  switch (error) {
    case DecodeError::TooShort:
      return "too short";
    case DecodeError::BadSync:
      return "bad sync";
    case DecodeError::BadHash:
      return "bad sync hash";
    case DecodeError::UnknownTlv:
      return "unknown TLV";
    case DecodeError::BadTlvLength:
      return "bad TLV length";
    case DecodeError::UnknownMessage:
      return "unknown message";
    case DecodeError::BadBody:
      return "bad body";
  }
  return "unknown";
}

uint32_t syncHash(std::span<const uint8_t> covered) {
  uint32_t h = 0;
  for (size_t i = 0; i < covered.size(); ++i) {
    uint8_t byte = covered[i];
    if (i >= 1 && i <= 3) byte = static_cast<uint8_t>("BTE"[i - 1]);
    h = h * 251 + byte;
  }
  return ((h * 251) >> 8) & 0xFFFFFF;
}

std::vector<uint8_t> encode(const Message& message) {
  Body body = bodyOf(message);
  std::vector<uint8_t> out;
  ByteWriter w(out);
  w.writeU8(kSync);
  w.writeU8(0);  // the hash goes here once the bytes it covers are written
  w.writeU16Be(0);
  uint32_t length = static_cast<uint32_t>(4 + 4 + body.bytes.size());
  w.writeU8(kTlvFourcc);
  w.writeU8(static_cast<uint8_t>(length >> 16));
  w.writeU16Be(static_cast<uint16_t>(length));
  w.writeBytes(std::span(reinterpret_cast<const uint8_t*>(body.fourcc.data()), 4));
  w.writeBytes(body.bytes);
  uint32_t h = syncHash(std::span(out).first(hashedSize(kTlvFourcc)));
  out[1] = static_cast<uint8_t>(h >> 16);
  out[2] = static_cast<uint8_t>(h >> 8);
  out[3] = static_cast<uint8_t>(h);
  return out;
}

Expected<Message, DecodeError> decode(std::span<const uint8_t> datagram) {
  if (datagram.size() < kSyncSize + 2) return unexpected(DecodeError::TooShort);
  if (datagram[0] != kSync) return unexpected(DecodeError::BadSync);
  uint8_t tag = datagram[kSyncSize];
  size_t hashed = hashedSize(tag);
  if (hashed == 0) return unexpected(DecodeError::UnknownTlv);
  if (datagram.size() < hashed) return unexpected(DecodeError::TooShort);
  uint32_t h = uint32_t{datagram[1]} << 16 | uint32_t{datagram[2]} << 8 | datagram[3];
  if (syncHash(datagram.first(hashed)) != h) return unexpected(DecodeError::BadHash);

  ByteReader r(datagram.subspan(kSyncSize));
  r.readU8();
  size_t header = tag == kTlvTwoccShort ? 2 : 4;
  size_t length = tag == kTlvTwoccShort ? r.readU8() : (size_t{r.readU8()} << 16 | r.readU16Be());
  size_t nameSize = tag == kTlvFourcc ? 4 : 2;
  if (length < header + nameSize || length - header > r.remaining())
    return unexpected(DecodeError::BadTlvLength);
  auto name = r.readBytes(nameSize);
  std::string fourcc(name.begin(), name.end());
  // Only the first TLV is the message; what follows it is not ours to read.
  ByteReader body(r.readBytes(length - header - nameSize));
  return decodeBody(fourcc, body);
}

}  // namespace wircam::btemp
