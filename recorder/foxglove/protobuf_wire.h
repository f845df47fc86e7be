// Protocol Buffers' wire format, the little of it an MCAP export writes
// (protobuf.dev/programming-guides/encoding): varints, 64-bit doubles and
// length-delimited fields, nested messages built inside out. The schemas
// are Foxglove's own .proto files; the bytes are checked by a reader we did
// not write (protobufjs, in the export tests).
#pragma once

#include <cstdint>
#include <cstring>
#include <string>
#include <string_view>

namespace wircam::recorder {

class ProtobufWriter {
 public:
  // Field `number` with a varint (int32, int64, enum, bool).
  ProtobufWriter& varint(uint32_t number, uint64_t value) {
    key(number, 0);
    return raw(value);
  }
  ProtobufWriter& number(uint32_t number, double value) {
    key(number, 1);
    char bytes[8];
    std::memcpy(bytes, &value, 8);  // little-endian on the machines we build for
    out_.append(bytes, 8);
    return *this;
  }
  // A string, bytes or a nested message's encoding.
  ProtobufWriter& bytes(uint32_t number, std::string_view value) {
    key(number, 2);
    raw(value.size());
    out_.append(value);
    return *this;
  }
  // Only the key and the length of a length-delimited field whose `size`
  // bytes the caller sends after these (a frame, not copied here).
  ProtobufWriter& lengthOnly(uint32_t number, size_t size) {
    key(number, 2);
    return raw(size);
  }
  const std::string& out() const { return out_; }

 private:
  void key(uint32_t number, uint32_t wireType) { raw(uint64_t{number} << 3 | wireType); }
  ProtobufWriter& raw(uint64_t value) {
    while (value >= 0x80) {
      out_.push_back(static_cast<char>(value | 0x80));
      value >>= 7;
    }
    out_.push_back(static_cast<char>(value));
    return *this;
  }
  std::string out_;
};

}  // namespace wircam::recorder
