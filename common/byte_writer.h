// Appends wire-format fields to a byte vector; the counterpart of ByteReader.
#pragma once

#include <cstdint>
#include <span>
#include <string_view>
#include <vector>

namespace wircam {

class ByteWriter {
 public:
  explicit ByteWriter(std::vector<uint8_t>& out) : out_(out) {}

  void writeU8(uint8_t v) { out_.push_back(v); }

  void writeU16Be(uint16_t v) {
    out_.push_back(static_cast<uint8_t>(v >> 8));
    out_.push_back(static_cast<uint8_t>(v));
  }

  void writeU32Be(uint32_t v) {
    for (int shift = 24; shift >= 0; shift -= 8) out_.push_back(static_cast<uint8_t>(v >> shift));
  }

  void writeU16Le(uint16_t v) {
    out_.push_back(static_cast<uint8_t>(v));
    out_.push_back(static_cast<uint8_t>(v >> 8));
  }

  void writeU32Le(uint32_t v) {
    for (int shift = 0; shift <= 24; shift += 8) out_.push_back(static_cast<uint8_t>(v >> shift));
  }

  void writeBytes(std::span<const uint8_t> bytes) {
    out_.insert(out_.end(), bytes.begin(), bytes.end());
  }

  // Callers check the length first; a longer text is cut at the field's width
  // so the layout can never be broken.
  void writeFixedString(std::string_view text, size_t width) {
    size_t n = text.size() < width ? text.size() : width;
    out_.insert(out_.end(), text.begin(), text.begin() + n);
    out_.insert(out_.end(), width - n, 0);
  }

 private:
  std::vector<uint8_t>& out_;
};

}  // namespace wircam
