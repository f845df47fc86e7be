// Bounds-checked reading of wire formats. Failure is sticky: after the first
// short read every read returns zero and ok() stays false, so a decoder reads
// all its fields and checks once at the end.
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>
#include <string>

namespace wircam {

class ByteReader {
 public:
  explicit ByteReader(std::span<const uint8_t> data) : data_(data) {}

  bool ok() const { return !failed_; }
  size_t remaining() const { return failed_ ? 0 : data_.size() - pos_; }
  size_t position() const { return pos_; }

  uint8_t readU8() {
    auto bytes = take(1);
    return bytes.empty() ? 0 : bytes[0];
  }

  uint16_t readU16Be() {
    auto b = take(2);
    return b.empty() ? 0 : static_cast<uint16_t>(b[0] << 8 | b[1]);
  }

  uint32_t readU32Be() {
    auto b = take(4);
    return b.empty() ? 0 : uint32_t{b[0]} << 24 | uint32_t{b[1]} << 16 | uint32_t{b[2]} << 8 | b[3];
  }

  uint16_t readU16Le() {
    auto b = take(2);
    return b.empty() ? 0 : static_cast<uint16_t>(b[1] << 8 | b[0]);
  }

  uint32_t readU32Le() {
    auto b = take(4);
    return b.empty() ? 0 : uint32_t{b[3]} << 24 | uint32_t{b[2]} << 16 | uint32_t{b[1]} << 8 | b[0];
  }

  // Returns an empty span (and fails) when fewer than n bytes are left.
  std::span<const uint8_t> readBytes(size_t n) { return take(n); }

  // A zero-padded ASCII field of fixed width: the text ends at the first zero
  // byte or at the end of the field, never beyond it.
  std::string readFixedString(size_t width) {
    auto field = take(width);
    size_t length = 0;
    while (length < field.size() && field[length] != 0) ++length;
    return std::string(field.begin(), field.begin() + length);
  }

  std::span<const uint8_t> readRest() { return take(remaining()); }

 private:
  std::span<const uint8_t> take(size_t n) {
    // Written as n <= size - pos so that a huge n cannot overflow the check.
    if (failed_ || n > data_.size() - pos_) {
      failed_ = true;
      return {};
    }
    auto bytes = data_.subspan(pos_, n);
    pos_ += n;
    return bytes;
  }

  std::span<const uint8_t> data_;
  size_t pos_ = 0;
  bool failed_ = false;
};

}  // namespace wircam
