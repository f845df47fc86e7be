// Stops a recording before the disk is full, so that the open segments can
// still be finished: their last clusters, cues and index need room too.
#pragma once

#include <cstdint>
#include <string>

namespace wircam::recorder {

// Bytes free for an unprivileged writer on the file system holding `path`;
// UINT64_MAX when it cannot be asked.
uint64_t freeBytes(const std::string& path);

class DiskGuard {
 public:
  explicit DiskGuard(std::string folder) : folder_(std::move(folder)) {}

  // The room kept free: 1 MiB for finishing the files plus 4 s of writing
  // at the current rate (what lands while the pipeline drains).
  static uint64_t reserveFor(uint64_t bytesPerSecond) { return (1 << 20) + 4 * bytesPerSecond; }

  // True when less than the reserve is free at `bytesPerSecond` of writing.
  bool nearlyFull(uint64_t bytesPerSecond) const;
  uint64_t free() const { return freeBytes(folder_); }

 private:
  std::string folder_;
};

}  // namespace wircam::recorder
