// How many files (sockets, timers, files on disk) this process may have
// open at once. Debian starts a process with a soft limit of 1024 under a
// hard limit hundreds of times higher (systemd's defaults: 1024 and
// 524288), for the sake of programs that still use select(); a program
// that needs more raises its own soft limit, up to the hard one. A camera
// of wirc-recorder holds about a dozen, so 1024 ran out at 80-odd cameras.
#pragma once

#include <cstdint>

namespace wircam {

// Raises the soft limit to the hard one; returns the limit now in force.
uint64_t raiseOpenFileLimit();

}  // namespace wircam
