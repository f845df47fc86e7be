#include "foxglove_client.h"

#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdio>

namespace wircam::testing {

FoxgloveClient::FoxgloveClient(std::vector<std::string> arguments) {
  int toChild[2], fromChild[2];
  if (pipe(toChild) != 0 || pipe(fromChild) != 0) return;
  arguments.insert(arguments.begin(), {"node", FOXGLOVE_CLIENT_DIR "/client.mjs"});
  pid_ = fork();
  if (pid_ == 0) {
    dup2(toChild[0], STDIN_FILENO);
    dup2(fromChild[1], STDOUT_FILENO);
    for (int fd : {toChild[0], toChild[1], fromChild[0], fromChild[1]}) close(fd);
    std::vector<char*> argv;
    for (auto& a : arguments) argv.push_back(a.data());
    argv.push_back(nullptr);
    execvp("node", argv.data());
    _exit(127);
  }
  close(toChild[0]);
  close(fromChild[1]);
  input_ = toChild[1];
  output_ = fromChild[0];
  reader_ = std::thread([this] { read(); });
}

FoxgloveClient::~FoxgloveClient() {
  if (pid_ > 0 && !exitCode_) {
    command({{"cmd", "exit"}});
    if (wait(std::chrono::seconds(5)) < 0) {
      kill(pid_, SIGKILL);
      waitpid(pid_, nullptr, 0);
    }
  }
  if (input_ >= 0) close(input_);
  if (reader_.joinable()) reader_.join();
  if (output_ >= 0) close(output_);
}

void FoxgloveClient::command(const nlohmann::json& command) {
  std::string line = command.dump() + "\n";
  signal(SIGPIPE, SIG_IGN);  // a client gone already: the write fails, the test goes on
  if (write(input_, line.data(), line.size()) < 0) return;
}

void FoxgloveClient::read() {
  FILE* in = fdopen(dup(output_), "r");
  char* line = nullptr;
  size_t capacity = 0;
  while (getline(&line, &capacity, in) > 0) {
    auto event = nlohmann::json::parse(line, nullptr, false);
    if (event.is_discarded()) continue;
    std::lock_guard lock(mutex_);
    events_.push_back(std::move(event));
    taken_.push_back(false);
    arrived_.notify_all();
  }
  free(line);
  fclose(in);
  std::lock_guard lock(mutex_);
  ended_ = true;
  arrived_.notify_all();
}

std::optional<nlohmann::json> FoxgloveClient::next(const std::string& name,
                                                   std::chrono::milliseconds timeout,
                                                   const Match& match) {
  auto end = std::chrono::steady_clock::now() + timeout;
  std::unique_lock lock(mutex_);
  size_t looked = 0;
  while (true) {
    for (; looked < events_.size(); ++looked) {
      if (taken_[looked] || events_[looked].value("event", "") != name) continue;
      if (match && !match(events_[looked])) continue;
      taken_[looked] = true;
      return events_[looked];
    }
    if (ended_) return std::nullopt;
    if (arrived_.wait_until(lock, end) == std::cv_status::timeout && looked == events_.size())
      return std::nullopt;
  }
}

std::vector<nlohmann::json> FoxgloveClient::events() const {
  std::lock_guard lock(mutex_);
  return events_;
}

int FoxgloveClient::wait(std::chrono::milliseconds timeout) {
  if (exitCode_) return *exitCode_;
  auto end = std::chrono::steady_clock::now() + timeout;
  while (std::chrono::steady_clock::now() < end) {
    int status = 0;
    if (waitpid(pid_, &status, WNOHANG) == pid_) {
      exitCode_ = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
      return *exitCode_;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  return -1;
}

}  // namespace wircam::testing
