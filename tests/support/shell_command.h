// A shell command as a user would run it: what it prints (stdout and
// stderr together) and how it exits.
#pragma once

#include <sys/wait.h>

#include <cstdio>
#include <string>

namespace wircam::testing {

struct CommandRun {
  int exitCode = -1;  // -1: it did not exit (a signal), or could not start
  std::string output;
};

inline CommandRun runCommand(const std::string& command) {
  CommandRun run;
  FILE* pipe = popen((command + " 2>&1").c_str(), "r");
  if (!pipe) return {-1, "popen failed"};
  char chunk[4096];
  while (size_t n = fread(chunk, 1, sizeof chunk, pipe)) run.output.append(chunk, n);
  int status = pclose(pipe);
  run.exitCode = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return run;
}

inline std::string commandOutput(const std::string& command) { return runCommand(command).output; }

}  // namespace wircam::testing
