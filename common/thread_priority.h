// A thread that others wait on (the links' loop, the disks' writers) runs
// ahead of the video work on busy processors:
// nice -10 for the calling thread. It needs CAP_SYS_NICE or an RLIMIT_NICE
// that allows it (the service's LimitNICE=); without either the thread
// keeps the process's priority, which is only slower.
#pragma once

#include <sys/resource.h>
#include <sys/syscall.h>
#include <unistd.h>

namespace wircam {

inline constexpr int kAheadNice = -10;

inline void runThisThreadAhead() {
  setpriority(PRIO_PROCESS, static_cast<id_t>(syscall(SYS_gettid)), kAheadNice);
}

}  // namespace wircam
