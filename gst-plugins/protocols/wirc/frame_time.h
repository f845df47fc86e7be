// A frame's time, from when its first packet arrived: never before the
// previous frame's (a frame completed late, after a newer one, would step
// time back from a segment's start), and at least a millisecond after it:
// Matroska keeps milliseconds, and two frames at one time read back as one
// stepping on the other (ffmpeg: "non monotonically increasing dts").
#pragma once

#include <algorithm>
#include <cstdint>
#include <optional>

namespace wircam::wirc {

constexpr uint64_t kMinFrameSpacingNs = 1'000'000;

constexpr uint64_t nextFrameTime(uint64_t arrivalNs, std::optional<uint64_t> previousNs) {
  return previousNs ? std::max(arrivalNs, *previousNs + kMinFrameSpacingNs) : arrivalNs;
}

}  // namespace wircam::wirc
