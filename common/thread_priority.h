// A thread that others wait on (the links' loop, the disks' writers) runs
// ahead of the video work on busy processors. Its work is small and
// bounded (a keepalive, a status; the bytes handed to it), but an equal
// share of saturated processors, or even nice -10's among hundreds of
// video threads, is less than it needs: measured, the disks' writer fell
// behind 256 cameras and their bounds filled.
//
// So the calling thread takes the lowest real-time priority (SCHED_RR 1),
// which runs it whenever it has work: that needs CAP_SYS_NICE or an
// RLIMIT_RTPRIO of 1 (the service's LimitRTPRIO=1). Without it, nice -10
// (CAP_SYS_NICE or RLIMIT_NICE, the service's LimitNICE=-10); without
// either, the process's priority, which is only slower.
//
// Such a thread must then never wait on a video thread, which the
// scheduler may leave preempted among hundreds: the locks it shares with
// them lend priority (priority_inheriting_mutex.h), and it neither mallocs
// nor frees in its loop (malloc's arena locks lend nothing).
#pragma once

#include <pthread.h>
#include <sched.h>
#include <sys/resource.h>
#include <sys/syscall.h>
#include <unistd.h>

namespace wircam {

inline constexpr int kAheadNice = -10;

inline void runThisThreadAhead() {
  sched_param realTime{};
  realTime.sched_priority = 1;
  if (pthread_setschedparam(pthread_self(), SCHED_RR, &realTime) == 0) return;
  setpriority(PRIO_PROCESS, static_cast<id_t>(syscall(SYS_gettid)), kAheadNice);
}

}  // namespace wircam
