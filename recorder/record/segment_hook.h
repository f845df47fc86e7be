// --on-segment-closed: a user's command (rclone, aws-cli, rsync, ...) run
// for each closed segment with its path and its sidecar's, never through a
// shell, on the GLib main loop. One runs at a time, in closing order; one
// that fails or outlives the timeout is stopped and retried with backoff
// (1, 2, 4, 8, 16 s; five tries), and every failure is logged and reported.
// Recording never waits on it: at most kMaxQueued segments wait, and what
// does not fit is reported, not held.
#pragma once

#include <glib.h>

#include <chrono>
#include <deque>
#include <functional>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

namespace wircam::recorder {

class SegmentHook {
 public:
  static constexpr size_t kMaxQueued = 100;
  static constexpr int kTries = 5;

  // `report` gets {"type":"hook-failed"|"hook-gave-up"|"hook-dropped", "file", ...}
  // for the segment's stream, on the main loop.
  using Report = std::function<void(const std::string& stream, const nlohmann::json& event)>;

  SegmentHook(std::vector<std::string> command, std::chrono::seconds timeout, Report report);
  ~SegmentHook();  // stops a running hook's process group
  SegmentHook(const SegmentHook&) = delete;
  SegmentHook& operator=(const SegmentHook&) = delete;

  void segmentClosed(const std::string& stream, const std::string& segment,
                     const std::string& sidecar);
  // Lets the queue run for up to `limit` (at exit); the segments it could
  // not hand over, by path.
  std::vector<std::string> drain(std::chrono::milliseconds limit);
  // Ends a drain now (a second SIGINT).
  void stopDraining() { drainStopped_ = true; }

 private:
  struct Job {
    std::string stream, segment, sidecar;
    int tries = 0;
  };
  void startNext();
  void finished(int status);
  void retryOrGiveUp(const std::string& why);
  static void onChildExit(GPid pid, gint status, gpointer self);
  static gboolean onTimeout(gpointer self);
  static gboolean onRetry(gpointer self);

  const std::vector<std::string> command_;
  const std::chrono::seconds timeout_;
  const Report report_;
  std::deque<Job> queue_;  // the first is running or waiting to retry
  GPid running_ = 0;
  guint timeoutSource_ = 0, retrySource_ = 0, childSource_ = 0;
  bool timedOut_ = false;
  bool drainStopped_ = false;
};

}  // namespace wircam::recorder
