// How much memory a process holds resident, and how many threads and file
// descriptors, for tests that a hostile peer or churning clients cannot
// make them grow.
#pragma once

#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>

namespace wircam::testing {

inline long residentKb(pid_t pid = getpid()) {
  std::ifstream status("/proc/" + std::to_string(pid) + "/status");
  std::string line;
  while (std::getline(status, line))
    if (line.rfind("VmRSS:", 0) == 0) return std::atol(line.c_str() + 6);
  return 0;
}

struct ProcessCounts {
  size_t threads = 0, descriptors = 0;
  size_t sockets = 0;  // of the descriptors
};

inline ProcessCounts processCounts(pid_t pid) {
  namespace fs = std::filesystem;
  std::string proc = "/proc/" + std::to_string(pid);
  ProcessCounts counts;
  for (const auto& entry : fs::directory_iterator(proc + "/task"))
    counts.threads += !entry.path().empty();
  for (const auto& entry : fs::directory_iterator(proc + "/fd")) {
    ++counts.descriptors;
    std::error_code error;
    counts.sockets += fs::read_symlink(entry.path(), error).string().starts_with("socket:");
  }
  return counts;
}

}  // namespace wircam::testing
