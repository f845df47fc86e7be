#include "child_process.h"

#include <signal.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <fstream>
#include <iterator>
#include <sstream>
#include <string>

namespace wircam::bench {

pid_t spawn(const std::string& command, const std::string& output, const std::string& errors) {
  pid_t pid = fork();
  if (pid == 0) {
    setpgid(0, 0);
    execl("/bin/sh", "sh", "-c", ("exec " + command + " >" + output + " 2>" + errors).c_str(),
          nullptr);
    _exit(127);
  }
  return pid;
}

void stopGroup(pid_t pid, int signal) { stopGroups({pid}, signal); }

void stopGroups(const std::vector<pid_t>& pids, int signal) {
  for (pid_t pid : pids) kill(-pid, signal);
  for (pid_t pid : pids) waitpid(pid, nullptr, 0);
}

Usage waitForUsage(pid_t pid, std::chrono::seconds giveUpAfter) {
  int status = 0;
  rusage usage{};
  auto deadline = std::chrono::steady_clock::now() + giveUpAfter;
  while (wait4(pid, &status, WNOHANG, &usage) == 0) {
    if (std::chrono::steady_clock::now() > deadline) {
      kill(-pid, SIGKILL);
      wait4(pid, &status, 0, &usage);
      break;
    }
    usleep(20000);
  }
  return {static_cast<double>(usage.ru_utime.tv_sec + usage.ru_stime.tv_sec) +
              static_cast<double>(usage.ru_utime.tv_usec + usage.ru_stime.tv_usec) / 1e6,
          usage.ru_maxrss, WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status)};
}

double cpuSecondsOf(pid_t pid) {
  std::ifstream stat("/proc/" + std::to_string(pid) + "/stat");
  std::string text((std::istreambuf_iterator<char>(stat)), {});
  std::istringstream in(text.substr(text.rfind(')') + 2));  // after the name, which may hold spaces
  std::string skip;
  for (int field = 3; field < 14; ++field) in >> skip;
  double user = 0, system = 0;  // fields 14 and 15, in clock ticks
  in >> user >> system;
  return (user + system) / static_cast<double>(sysconf(_SC_CLK_TCK));
}

}  // namespace wircam::bench
