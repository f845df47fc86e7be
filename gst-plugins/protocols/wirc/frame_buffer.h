// A growable byte buffer that, unlike std::vector, does not zero what it
// allocates: the assembler writes every byte of a frame exactly once.
#pragma once

#include <cstdint>
#include <cstring>
#include <memory>
#include <span>

namespace wircam::wirc {

class FrameBuffer {
 public:
  FrameBuffer() = default;
  explicit FrameBuffer(size_t capacity) { reserve(capacity); }

  uint8_t* data() { return data_.get(); }
  const uint8_t* data() const { return data_.get(); }
  size_t size() const { return size_; }
  size_t capacity() const { return capacity_; }
  std::span<const uint8_t> bytes() const { return {data_.get(), size_}; }

  // Keeps the first size() bytes.
  void reserve(size_t capacity) {
    if (capacity <= capacity_) return;
    auto grown = std::make_unique_for_overwrite<uint8_t[]>(capacity);
    if (size_ > 0) std::memcpy(grown.get(), data_.get(), size_);
    data_ = std::move(grown);
    capacity_ = capacity;
  }

  // The caller has written (or will write) bytes up to size; capacity must
  // already allow it.
  void setSize(size_t size) { size_ = size; }

 private:
  std::unique_ptr<uint8_t[]> data_;
  size_t capacity_ = 0;
  size_t size_ = 0;
};

}  // namespace wircam::wirc
