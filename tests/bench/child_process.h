// Sender and receiver processes for the real-time bench tools.
#pragma once

#include <sys/types.h>

#include <chrono>
#include <string>
#include <vector>

namespace wircam::bench {

// Runs `command` through sh in a process group of its own, its stdout to
// `output`, its stderr to `errors` ("&1": where stdout goes).
pid_t spawn(const std::string& command, const std::string& output = "/dev/null",
            const std::string& errors = "/dev/null");

// Signals the whole group and waits for its leader.
void stopGroup(pid_t pid, int signal);
// The same for many at once: all are signalled before any is waited for,
// so they stop together (one by one, 200 senders take seconds).
void stopGroups(const std::vector<pid_t>& pids, int signal);

// Waits for a child and says what it used: CPU (user + system) and peak
// memory, and how it ended. One still running after `giveUpAfter` is
// killed with its group (exit code 137), so a receiver that never stops
// cannot hang the whole bench.
struct Usage {
  double cpuSeconds = 0;
  long maxRssKb = 0;
  int exitCode = 0;  // 128 + the signal that ended it
};
Usage waitForUsage(pid_t pid, std::chrono::seconds giveUpAfter = std::chrono::seconds(60));

// A running process's user + system CPU seconds so far (/proc/PID/stat),
// for one that keeps running across measurements.
double cpuSecondsOf(pid_t pid);

}  // namespace wircam::bench
