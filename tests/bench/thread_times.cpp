#include "thread_times.h"

#include <filesystem>
#include <fstream>
#include <sstream>

namespace wircam::bench {

namespace fs = std::filesystem;

ThreadTimes threadTimes() {
  ThreadTimes times;
  for (const auto& task : fs::directory_iterator("/proc/self/task")) {
    std::string name;
    std::getline(std::ifstream(task.path() / "comm"), name);
    ThreadTime time;
    std::ifstream(task.path() / "schedstat") >> time.cpuNs;
    std::ifstream status(task.path() / "status");
    for (std::string line; std::getline(status, line);) {
      std::istringstream fields(line);
      std::string key;
      if (fields >> key && key == "voluntary_ctxt_switches:") fields >> time.wakeUps;
    }
    auto& sum = times[name];
    sum.cpuNs += time.cpuNs;
    sum.wakeUps += time.wakeUps;
  }
  return times;
}

ThreadTimes operator-(const ThreadTimes& after, const ThreadTimes& before) {
  ThreadTimes spent;
  for (const auto& [name, time] : after) {
    auto earlier = before.find(name);
    ThreadTime start = earlier == before.end() ? ThreadTime{} : earlier->second;
    // A thread of this name that ended in between makes the sum shrink.
    spent[name] = {time.cpuNs > start.cpuNs ? time.cpuNs - start.cpuNs : 0,
                   time.wakeUps > start.wakeUps ? time.wakeUps - start.wakeUps : 0};
  }
  return spent;
}

}  // namespace wircam::bench
