// Where a process's CPU goes, thread by thread: each thread's time on a
// processor (ns, /proc/self/task/TID/schedstat) and how often it went to
// sleep and woke again (its voluntary context switches). Two snapshots
// subtracted give one window's figures; threads are keyed by their name,
// so "wircsrc0:src" (a source's streaming thread) is told from the rest.
#pragma once

#include <cstdint>
#include <map>
#include <string>

namespace wircam::bench {

struct ThreadTime {
  uint64_t cpuNs = 0;
  uint64_t wakeUps = 0;
};

// Per thread name, summed over threads of the same name.
using ThreadTimes = std::map<std::string, ThreadTime>;

ThreadTimes threadTimes();
// What each thread spent between two snapshots (threads born in between count whole).
ThreadTimes operator-(const ThreadTimes& after, const ThreadTimes& before);

}  // namespace wircam::bench
