#include "app/open_files_check.h"

namespace wircam::recorder {

namespace {
// A camera's dozen, with room for a segment's next files; and, besides
// the cameras, the servers and the logs.
constexpr uint64_t kFilesPerCamera = 16;
constexpr uint64_t kFilesBesideCameras = 64;
}  // namespace

std::optional<std::string> openFilesShortfall(uint64_t cameras, uint64_t limit) {
  uint64_t wanted = cameras * kFilesPerCamera + kFilesBesideCameras;
  if (limit >= wanted) return std::nullopt;
  std::string need = std::to_string(wanted);
  return std::to_string(cameras) + " cameras may need " + need +
         " open files, and this process may open " + std::to_string(limit) +
         ": raise the limit (`ulimit -n " + need + "` in its shell, LimitNOFILE=" + need +
         " in its systemd unit) or some cameras will not start";
}

}  // namespace wircam::recorder
