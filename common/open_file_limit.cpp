#include "common/open_file_limit.h"

#include <sys/resource.h>

namespace wircam {

uint64_t raiseOpenFileLimit() {
  rlimit limit{};
  if (getrlimit(RLIMIT_NOFILE, &limit) != 0) return 0;
  if (limit.rlim_cur < limit.rlim_max) {
    // A hard limit of "unlimited" is not a soft one the kernel takes
    // (fs.nr_open bounds it): the soft limit then stays as it was.
    rlimit raised{.rlim_cur = limit.rlim_max, .rlim_max = limit.rlim_max};
    if (setrlimit(RLIMIT_NOFILE, &raised) == 0) limit = raised;
  }
  return limit.rlim_cur;
}

}  // namespace wircam
