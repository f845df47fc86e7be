#include "child_process.h"

#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

namespace wircam::bench {

pid_t spawn(const std::string& command, const std::string& output) {
  pid_t pid = fork();
  if (pid == 0) {
    setpgid(0, 0);
    execl("/bin/sh", "sh", "-c", ("exec " + command + " >" + output + " 2>/dev/null").c_str(),
          nullptr);
    _exit(127);
  }
  return pid;
}

void stopGroup(pid_t pid, int signal) {
  kill(-pid, signal);
  waitpid(pid, nullptr, 0);
}

}  // namespace wircam::bench
