// The mutex lends its holder a waiter's priority (what keeps the links'
// loop and the disks' writer from waiting behind a preempted video
// thread), and its condition waits on the steady clock.
#include "common/priority_inheriting_mutex.h"

#include <gtest/gtest.h>
#include <pthread.h>
#include <sched.h>

#include <atomic>
#include <chrono>
#include <mutex>
#include <thread>

namespace {

using wircam::MutexLock;
using wircam::PriorityInheritingCondition;
using wircam::PriorityInheritingMutex;
using Clock = std::chrono::steady_clock;
using namespace std::chrono_literals;

// Runs the calling thread on processor 0 at SCHED_FIFO `priority` (0: the
// ordinary policy); false when this process may not.
bool runOnProcessorZeroAt(int priority) {
  cpu_set_t one;
  CPU_ZERO(&one);
  CPU_SET(0, &one);
  if (pthread_setaffinity_np(pthread_self(), sizeof one, &one) != 0) return false;
  sched_param param{};
  param.sched_priority = priority;
  return pthread_setschedparam(pthread_self(), priority ? SCHED_FIFO : SCHED_OTHER, &param) == 0;
}

void spinFor(std::chrono::milliseconds span) {
  auto end = Clock::now() + span;
  while (Clock::now() < end) {
  }
}

// The textbook inversion, on one processor: a low thread holds the lock, a
// middle one (real-time) spins, a high one (real-time, above it) wants the
// lock. With an ordinary mutex the high one waits out the middle one's
// whole spin; lent its priority, the low thread runs at once and lets go.
TEST(PriorityInheritingMutex, TheHolderRunsAheadOfAMiddleThreadWhileAHighOneWaits) {
  PriorityInheritingMutex mutex;
  std::atomic<bool> held{false}, highWaiting{false}, highGotIt{false};
  bool highGotItFirst = false;  // before the middle thread's spin ended
  std::atomic<bool> allowed{true};
  std::thread low([&] {
    allowed = allowed && runOnProcessorZeroAt(0);
    MutexLock lock(mutex);
    held = true;
    while (!highWaiting) std::this_thread::yield();
    spinFor(5ms);  // its work under the lock
  });
  while (!held) std::this_thread::sleep_for(1ms);
  std::thread high([&] {
    allowed = allowed && runOnProcessorZeroAt(2);
    highWaiting = true;
    MutexLock lock(mutex);
    highGotIt = true;
  });
  std::thread middle([&] {
    if (!runOnProcessorZeroAt(1)) {
      allowed = false;
      return;
    }
    while (!highWaiting) std::this_thread::yield();
    spinFor(150ms);
    highGotItFirst = highGotIt;
  });
  middle.join();
  high.join();
  low.join();
  if (!allowed) GTEST_SKIP() << "real-time priorities are not allowed here";
  EXPECT_TRUE(highGotItFirst);
}

TEST(PriorityInheritingCondition, WaitsUntilNotifiedOrForItsTimeout) {
  PriorityInheritingMutex mutex;
  PriorityInheritingCondition condition;
  bool ready = false;
  {
    MutexLock lock(mutex);
    auto start = Clock::now();
    EXPECT_FALSE(condition.waitFor(mutex, 30ms, [&] { return ready; }));
    EXPECT_GE(Clock::now() - start, 30ms);
  }
  std::thread notifier([&] {
    std::this_thread::sleep_for(10ms);
    MutexLock lock(mutex);
    ready = true;
    condition.notifyAll();
  });
  {
    MutexLock lock(mutex);
    EXPECT_TRUE(condition.waitFor(mutex, 10s, [&] { return ready; }));
  }
  notifier.join();
}

}  // namespace
