// GLib before 2.76 (Debian 12 has 2.74) gives every thread its own GSlice
// magazines: caches of freed GStreamer structures, events and buffers that
// stay with the thread. A recorder runs two streaming threads per camera, so
// those caches cost about 58 KB a camera (3.7 MB at 64 cameras). GLib 2.76
// dropped them for plain malloc, and G_SLICE=always-malloc asks 2.74 for the
// same; but GLib reads it once, in its own constructors, before main() runs,
// and a setenv from an executable's .preinit_array is undone by libc's own
// start. So the process starts once more with it set.
#include "app/slice_allocator.h"

#include <glib.h>
#include <unistd.h>

#include <cstdlib>

namespace wircam::recorder {

void useMallocForSlices(char** argv) {
  if (glib_check_version(2, 76, 0) == nullptr || std::getenv("G_SLICE") != nullptr) return;
  setenv("G_SLICE", "always-malloc", 1);
  // The executable's own path, not /proc/self/exe: the process is named
  // after the file it runs (its comm, what top, pgrep and killall show).
  char self[4096];
  ssize_t length = readlink("/proc/self/exe", self, sizeof self - 1);
  if (length <= 0) return;
  self[length] = '\0';
  execv(self, argv);
  // Not restarted (no /proc?): the magazines stay, and nothing else changes.
}

}  // namespace wircam::recorder
