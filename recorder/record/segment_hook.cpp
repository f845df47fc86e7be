#include "record/segment_hook.h"

#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdio>

#include "log_line.h"

namespace wircam::recorder {

namespace {

// In a process group of its own, so a timeout stops what it started too.
void ownProcessGroup(gpointer) { setpgid(0, 0); }

std::string describe(int status) {
  if (WIFEXITED(status)) return "exited with " + std::to_string(WEXITSTATUS(status));
  if (WIFSIGNALED(status)) return std::string("killed by signal ") + strsignal(WTERMSIG(status));
  return "ended with status " + std::to_string(status);
}

}  // namespace

SegmentHook::SegmentHook(std::vector<std::string> command, std::chrono::seconds timeout,
                         Report report)
    : command_(std::move(command)), timeout_(timeout), report_(std::move(report)) {}

SegmentHook::~SegmentHook() {
  for (guint source : {timeoutSource_, retrySource_, childSource_})
    if (source) g_source_remove(source);
  if (running_) {
    kill(-running_, SIGKILL);
    waitpid(running_, nullptr, 0);
    g_spawn_close_pid(running_);
  }
}

void SegmentHook::segmentClosed(const std::string& stream, const std::string& segment,
                                const std::string& sidecar) {
  if (queue_.size() >= kMaxQueued) {
    logLine("--on-segment-closed is " + std::to_string(queue_.size()) +
            " segments behind; not handing over " + segment);
    report_(stream, {{"type", "hook-dropped"}, {"file", segment}});
    return;
  }
  queue_.push_back({stream, segment, sidecar});
  if (queue_.size() == 1) startNext();
}

void SegmentHook::startNext() {
  if (queue_.empty() || running_ || retrySource_) return;
  Job& job = queue_.front();
  ++job.tries;
  std::vector<gchar*> argv;
  for (const auto& part : command_) argv.push_back(const_cast<gchar*>(part.c_str()));
  argv.push_back(const_cast<gchar*>(job.segment.c_str()));
  argv.push_back(const_cast<gchar*>(job.sidecar.c_str()));
  argv.push_back(nullptr);
  GError* error = nullptr;
  auto flags = static_cast<GSpawnFlags>(G_SPAWN_SEARCH_PATH | G_SPAWN_DO_NOT_REAP_CHILD);
  if (!g_spawn_async(nullptr, argv.data(), nullptr, flags, ownProcessGroup, nullptr, &running_,
                     &error)) {
    std::string why = error->message;
    g_error_free(error);
    running_ = 0;
    return retryOrGiveUp("cannot start: " + why);
  }
  timedOut_ = false;
  childSource_ = g_child_watch_add(running_, onChildExit, this);
  timeoutSource_ = g_timeout_add_seconds(static_cast<guint>(timeout_.count()), onTimeout, this);
}

void SegmentHook::onChildExit(GPid pid, gint status, gpointer data) {
  auto* self = static_cast<SegmentHook*>(data);
  g_spawn_close_pid(pid);
  self->childSource_ = 0;
  self->running_ = 0;
  if (self->timeoutSource_) g_source_remove(self->timeoutSource_);
  self->timeoutSource_ = 0;
  self->finished(status);
}

gboolean SegmentHook::onTimeout(gpointer data) {
  auto* self = static_cast<SegmentHook*>(data);
  self->timeoutSource_ = 0;
  self->timedOut_ = true;
  if (self->running_) kill(-self->running_, SIGKILL);  // the child watch reports it
  return G_SOURCE_REMOVE;
}

void SegmentHook::finished(int status) {
  GError* error = nullptr;
  if (!timedOut_ && g_spawn_check_wait_status(status, &error)) {
    queue_.pop_front();
    return startNext();
  }
  if (error) g_error_free(error);
  retryOrGiveUp(timedOut_ ? "ran longer than " + std::to_string(timeout_.count()) + " s"
                          : describe(status));
}

void SegmentHook::retryOrGiveUp(const std::string& why) {
  Job& job = queue_.front();
  bool last = job.tries >= kTries;
  std::string what = "--on-segment-closed for " + job.segment + " " + why + " (try " +
                     std::to_string(job.tries) + " of " + std::to_string(kTries) + ")";
  report_(job.stream, {{"type", last ? "hook-gave-up" : "hook-failed"},
                       {"file", job.segment},
                       {"try", job.tries},
                       {"reason", why}});
  if (last) {
    logLine(what + "; giving up on it");
    queue_.pop_front();
    return startNext();
  }
  guint delay = 1u << (job.tries - 1);
  logLine(what + "; again in " + std::to_string(delay) + " s");
  retrySource_ = g_timeout_add_seconds(delay, onRetry, this);
}

gboolean SegmentHook::onRetry(gpointer data) {
  auto* self = static_cast<SegmentHook*>(data);
  self->retrySource_ = 0;
  self->startNext();
  return G_SOURCE_REMOVE;
}

std::vector<std::string> SegmentHook::drain(std::chrono::milliseconds limit) {
  auto end = std::chrono::steady_clock::now() + limit;
  // A tick, so a retry waiting longer than the limit does not hold it up.
  guint tick = g_timeout_add(
      200, [](gpointer) -> gboolean { return G_SOURCE_CONTINUE; }, nullptr);
  while (!queue_.empty() && !drainStopped_ && std::chrono::steady_clock::now() < end)
    g_main_context_iteration(nullptr, TRUE);
  g_source_remove(tick);
  std::vector<std::string> left;
  for (const auto& job : queue_) left.push_back(job.segment);
  return left;
}

}  // namespace wircam::recorder
