// Frame buffers coming back once what wrapped them downstream (a GstBuffer)
// was freed, on whatever thread, for the assembler to fill again. A camera
// then reuses a couple of blocks instead of taking a fresh one from malloc
// for every frame: hundreds of cameras' threads doing that through malloc's
// shared arenas left freed frames behind as holes, and the recorder grew.
#pragma once

#include <mutex>
#include <optional>
#include <vector>

#include "wirc/frame_buffer.h"

namespace wircam::wirc {

class FrameBufferReturns {
 public:
  // More than this many waiting are freed: a burst's extra buffers are not kept.
  static constexpr size_t kMaxWaiting = 2;

  // Any thread.
  void put(FrameBuffer&& buffer) {
    std::lock_guard lock(mutex_);
    if (waiting_.size() < kMaxWaiting) waiting_.push_back(std::move(buffer));
  }
  std::optional<FrameBuffer> take() {
    std::lock_guard lock(mutex_);
    if (waiting_.empty()) return std::nullopt;
    FrameBuffer buffer = std::move(waiting_.back());
    waiting_.pop_back();
    return buffer;
  }

 private:
  std::mutex mutex_;
  std::vector<FrameBuffer> waiting_;
};

}  // namespace wircam::wirc
