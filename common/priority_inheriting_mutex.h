// A mutex that lends whoever holds it the priority of the highest thread
// waiting for it (PTHREAD_PRIO_INHERIT), and a condition variable to wait
// with it. For the locks a thread that runs ahead (thread_priority.h)
// shares with the video threads: on saturated processors, a video thread
// preempted while it holds an ordinary mutex keeps the real-time thread
// waiting for as long as the scheduler leaves it out, up to hundreds of
// milliseconds among hundreds of threads (priority inversion). Lent the
// priority, it runs at once, up to its unlock.
//
// Uncontended, it costs what std::mutex does (a compare-and-swap); the
// kernel is asked only when a thread must wait.
#pragma once

#include <pthread.h>
#include <time.h>

#include <chrono>

#include "common/mutex.h"

namespace wircam {

class WIRCAM_CAPABILITY("mutex") PriorityInheritingMutex {
 public:
  PriorityInheritingMutex() {
    pthread_mutexattr_t attributes;
    pthread_mutexattr_init(&attributes);
    pthread_mutexattr_setprotocol(&attributes, PTHREAD_PRIO_INHERIT);
    pthread_mutex_init(&mutex_, &attributes);
    pthread_mutexattr_destroy(&attributes);
  }
  ~PriorityInheritingMutex() { pthread_mutex_destroy(&mutex_); }
  PriorityInheritingMutex(const PriorityInheritingMutex&) = delete;
  PriorityInheritingMutex& operator=(const PriorityInheritingMutex&) = delete;

  void lock() WIRCAM_ACQUIRE() { pthread_mutex_lock(&mutex_); }
  void unlock() WIRCAM_RELEASE() { pthread_mutex_unlock(&mutex_); }

 private:
  friend class PriorityInheritingCondition;
  pthread_mutex_t mutex_;
};

// Waits on the steady clock, as std::condition_variable does.
class PriorityInheritingCondition {
 public:
  PriorityInheritingCondition() {
    pthread_condattr_t attributes;
    pthread_condattr_init(&attributes);
    pthread_condattr_setclock(&attributes, CLOCK_MONOTONIC);
    pthread_cond_init(&condition_, &attributes);
    pthread_condattr_destroy(&attributes);
  }
  ~PriorityInheritingCondition() { pthread_cond_destroy(&condition_); }
  PriorityInheritingCondition(const PriorityInheritingCondition&) = delete;
  PriorityInheritingCondition& operator=(const PriorityInheritingCondition&) = delete;

  void notifyOne() { pthread_cond_signal(&condition_); }
  void notifyAll() { pthread_cond_broadcast(&condition_); }

  // With `mutex` held (let go while waiting): until `ready()`. A `ready`
  // that reads fields the mutex guards says so: [&]() WIRCAM_REQUIRES(m).
  template <class Ready>
  void wait(PriorityInheritingMutex& mutex, Ready ready)
      WIRCAM_REQUIRES(mutex) WIRCAM_NO_THREAD_SAFETY_ANALYSIS {
    while (!ready()) pthread_cond_wait(&condition_, &mutex.mutex_);
  }
  // The same, for at most `timeout`; what `ready()` says at the end.
  template <class Ready>
  bool waitFor(PriorityInheritingMutex& mutex, std::chrono::nanoseconds timeout, Ready ready)
      WIRCAM_REQUIRES(mutex) WIRCAM_NO_THREAD_SAFETY_ANALYSIS {
    timespec until{};
    clock_gettime(CLOCK_MONOTONIC, &until);
    auto ns = static_cast<long long>(until.tv_nsec) + timeout.count();
    until.tv_sec += static_cast<time_t>(ns / 1'000'000'000);
    until.tv_nsec = static_cast<long>(ns % 1'000'000'000);
    while (!ready())
      if (pthread_cond_timedwait(&condition_, &mutex.mutex_, &until) != 0) return ready();
    return true;
  }

 private:
  pthread_cond_t condition_;
};

}  // namespace wircam
