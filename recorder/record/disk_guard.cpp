#include "record/disk_guard.h"

#include <sys/statvfs.h>

namespace wircam::recorder {

uint64_t freeBytes(const std::string& path) {
  struct statvfs info {};
  if (statvfs(path.c_str(), &info) != 0) return UINT64_MAX;
  return static_cast<uint64_t>(info.f_bavail) * info.f_frsize;
}

bool DiskGuard::nearlyFull(uint64_t bytesPerSecond) const {
  return freeBytes(folder_) < reserveFor(bytesPerSecond);
}

}  // namespace wircam::recorder
