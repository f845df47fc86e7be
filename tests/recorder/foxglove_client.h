// A Foxglove WebSocket client we did not write the protocol of:
// foxglove_client/client.mjs, on @foxglove/ws-protocol's FoxgloveClient
// under node, driven through its stdin (one JSON command a line) and read
// from its stdout (one JSON event a line), as the Foxglove tests use it.
#pragma once

#include <sys/types.h>

#include <chrono>
#include <condition_variable>
#include <functional>
#include <mutex>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <thread>
#include <vector>

namespace wircam::testing {

class FoxgloveClient {
 public:
  // `arguments` after client.mjs: {"--url", URL} and more (see client.mjs).
  explicit FoxgloveClient(std::vector<std::string> arguments);
  ~FoxgloveClient();  // exits it (killed if it does not)
  FoxgloveClient(const FoxgloveClient&) = delete;
  FoxgloveClient& operator=(const FoxgloveClient&) = delete;

  void command(const nlohmann::json& command);
  using Match = std::function<bool(const nlohmann::json&)>;
  // The first event named `name` (that `match` accepts) not taken by an
  // earlier call, or nullopt after `timeout`.
  std::optional<nlohmann::json> next(const std::string& name, std::chrono::milliseconds timeout,
                                     const Match& match = {});
  // Every event so far.
  std::vector<nlohmann::json> events() const;
  // Waits for the process's exit (the churn mode): its exit code, or -1.
  int wait(std::chrono::milliseconds timeout);

 private:
  void read();

  pid_t pid_ = -1;
  int input_ = -1, output_ = -1;
  std::thread reader_;
  mutable std::mutex mutex_;
  std::condition_variable arrived_;
  std::vector<nlohmann::json> events_;
  std::vector<bool> taken_;  // by next(), one flag an event
  bool ended_ = false;
  std::optional<int> exitCode_;
};

}  // namespace wircam::testing
