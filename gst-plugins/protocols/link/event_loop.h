// The one event loop (sockets + timers) on which every vehicle link of a
// process runs: a single thread around epoll, so a recorder of 200 vehicles
// stays a handful of threads. Callbacks run on the loop thread and must not
// block; anything may be registered or removed from any thread.
//
// The loop runs ahead of the video threads (thread_priority.h), so what it
// shares with them must not hold it behind one preempted: its lock lends
// priority, and re-arming a timer reuses the timer's node in the queue (a
// malloc could wait on an arena's lock, which lends nothing).
#pragma once

#include <atomic>
#include <chrono>
#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <thread>

#include "common/priority_inheriting_mutex.h"
#include "common/socket.h"

namespace wircam::link {

using Clock = std::chrono::steady_clock;

class EventLoop {
 public:
  using Id = uint64_t;
  using Callback = std::function<void()>;
  using IoCallback = std::function<void(uint32_t events)>;  // EPOLLIN, EPOLLOUT, ...

  // The process's loop, started on first use and never torn down (plugins
  // may be unloaded in any order at exit).
  static EventLoop& shared();

  EventLoop();
  ~EventLoop();
  EventLoop(const EventLoop&) = delete;
  EventLoop& operator=(const EventLoop&) = delete;

  // Calls `callback` with the ready events of `fd` until unwatched.
  Id watch(int fd, uint32_t events, IoCallback callback);
  void setEvents(Id watch, uint32_t events);

  // A timer fires once per arm(); arming again moves it. A disarm from
  // another thread that races the due time may still see it fire once, so
  // timer callbacks work out what is due from their own state.
  //
  // Timers due within kCoalesce of the one that wakes the loop fire with it
  // (early): 200 links' deadlines share wake-ups instead of each paying one
  // (the links' keepalives, on alarms of their own, share a grid
  // kCoalesce apart: link/alarm.h). The loop sleeps on a timerfd set to
  // its earliest timer, so a timer moved later from another thread never
  // wakes it, and one moved earlier wakes it only when due.
  static constexpr std::chrono::milliseconds kCoalesce{10};
  Id addTimer(Callback callback);
  void arm(Id timer, Clock::time_point when);
  void disarm(Id timer);

  // Unwatches or deletes a timer. Once it returns, the callback is not
  // running and never runs again (unless called from that very callback).
  void remove(Id id);

  // Runs `task` on the loop thread and waits for it; inline when already
  // there. Tasks must not block, so the wait is bounded by the loop's work.
  void invoke(const Callback& task);
  bool inLoopThread() const { return std::this_thread::get_id() == thread_.get_id(); }
  // How often the loop thread has woken (for tests and benchmarks).
  uint64_t wakeUps() const { return wakeUps_; }

 private:
  using TimerQueue = std::multimap<Clock::time_point, Id>;
  struct Entry {
    int fd = -1;  // -1 for timers
    // Shared so that the loop can run one while remove() drops the entry.
    std::shared_ptr<const Callback> onTimer;
    std::shared_ptr<const IoCallback> onIo;
    std::optional<TimerQueue::iterator> queued;  // armed: its place in timers_
    TimerQueue::node_type spare;                 // disarmed: its node, for the next arm
  };

  void run();
  void wake();
  void waitUntilIdle(Id id) WIRCAM_REQUIRES(mutex_);
  void unqueue(Entry& entry) WIRCAM_REQUIRES(mutex_);
  // Sets the timerfd to the earliest timer, if that changed.
  void followEarliestTimer() WIRCAM_REQUIRES(mutex_);

  UniqueFd epoll_;
  UniqueFd wake_;
  UniqueFd alarm_;  // a timerfd: the earliest timer's due time
  std::thread thread_;

  // Guards what is marked so; never held while a callback runs.
  mutable PriorityInheritingMutex mutex_;
  PriorityInheritingCondition idle_;  // a callback finished
  std::map<Id, Entry> entries_ WIRCAM_GUARDED_BY(mutex_);
  TimerQueue timers_ WIRCAM_GUARDED_BY(mutex_);  // armed timers by due time
  Id nextId_ WIRCAM_GUARDED_BY(mutex_) = 1;
  Id running_ WIRCAM_GUARDED_BY(mutex_) = 0;  // the entry whose callback runs now
  bool stopping_ WIRCAM_GUARDED_BY(mutex_) = false;
  std::optional<Clock::time_point> alarmTime_
      WIRCAM_GUARDED_BY(mutex_);  // what alarm_ is set to, if it has not fired
  std::atomic<uint64_t> wakeUps_ = 0;
};

}  // namespace wircam::link
