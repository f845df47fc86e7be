// wirc-sim as a user runs it: a process that ends on SIGINT, SIGTERM or
// its --duration, and on nothing else.
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <optional>
#include <regex>
#include <string>
#include <vector>

#include "shell_command.h"
#include "wait_for.h"

namespace {

using std::chrono::milliseconds;
using wircam::testing::runCommand;
using wircam::testing::waitFor;

struct Simulator {
  pid_t pid = -1;
  std::filesystem::path output;
};

// Starts wirc-sim with `arguments` on an ephemeral loopback port, its
// output to a file of its own.
Simulator startSimulator(std::vector<std::string> arguments) {
  static int count = 0;
  Simulator sim{.output = std::filesystem::temp_directory_path() /
                          ("wirc-sim-process-" + std::to_string(getpid()) + "-" +
                           std::to_string(++count) + ".log")};
  arguments.insert(arguments.begin(), {std::string(WIRCAM_BIN_DIR) + "/wirc-sim", "--bind",
                                       "127.0.0.1", "--port", "0"});
  sim.pid = fork();
  if (sim.pid == 0) {
    std::vector<char*> argv;
    for (auto& argument : arguments) argv.push_back(argument.data());
    argv.push_back(nullptr);
    if (!freopen(sim.output.c_str(), "w", stdout) || !freopen("/dev/null", "w", stderr)) _exit(126);
    execv(argv[0], argv.data());
    _exit(127);
  }
  return sim;
}

// The port it says it listens on, once it has said so.
std::optional<std::string> portOf(const Simulator& sim) {
  std::ifstream in(sim.output);
  std::string text((std::istreambuf_iterator<char>(in)), {});
  std::smatch found;
  if (!std::regex_search(text, found, std::regex("listening on 127\\.0\\.0\\.1:([0-9]+)")))
    return std::nullopt;
  return found[1].str();
}

// Its state letter in /proc (R, S, T stopped, Z ended), or '\0' once gone.
char stateOf(pid_t pid) {
  std::ifstream stat("/proc/" + std::to_string(pid) + "/stat");
  std::string line;
  if (!std::getline(stat, line)) return '\0';
  auto after = line.rfind(')');
  return after == std::string::npos || after + 2 >= line.size() ? '\0' : line[after + 2];
}

// A stop and a continue (Ctrl-Z, then fg or bg) interrupt its wait for a
// signal: that wait, not retried, ended the run at once and dropped every
// receiver (a stranger's trial).
TEST(WircSimProcess, RunsOnThroughAStopAndAContinue) {
  for (std::vector<std::string> arguments :
       {std::vector<std::string>{}, std::vector<std::string>{"--duration", "60"}}) {
    std::string which = arguments.empty() ? "without --duration" : "with --duration";
    Simulator sim = startSimulator(arguments);
    ASSERT_GT(sim.pid, 0);
    std::optional<std::string> port;
    ASSERT_TRUE(waitFor([&] { return (port = portOf(sim)).has_value(); })) << which;
    kill(sim.pid, SIGTSTP);
    kill(sim.pid, SIGSTOP);
    ASSERT_TRUE(waitFor([&] { return stateOf(sim.pid) == 'T'; })) << which;
    kill(sim.pid, SIGCONT);
    ASSERT_TRUE(waitFor([&] { return stateOf(sim.pid) != 'T'; })) << which;
    // Still the device: a login answers (it had ended by then).
    auto info = runCommand(std::string(WIRCAM_BIN_DIR) + "/wirc-cli info --host 127.0.0.1 --port " +
                           *port + " --timeout 3000");
    EXPECT_EQ(info.exitCode, 0) << which << ": " << info.output;
    EXPECT_NE(stateOf(sim.pid), 'Z') << which;
    kill(sim.pid, SIGINT);
    int status = 0;
    waitpid(sim.pid, &status, 0);
    EXPECT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0) << which;
    std::filesystem::remove(sim.output);
  }
}

TEST(WircSimProcess, EndsAtItsDuration) {
  auto start = std::chrono::steady_clock::now();
  Simulator sim = startSimulator({"--duration", "0.5"});
  int status = 0;
  waitpid(sim.pid, &status, 0);
  EXPECT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0);
  EXPECT_GE(std::chrono::steady_clock::now() - start, milliseconds(500));
  std::filesystem::remove(sim.output);
}

}  // namespace
