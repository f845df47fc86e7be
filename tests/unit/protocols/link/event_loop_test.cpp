// The event loop: timers, watches, and removal that waits for a callback.
#include "link/event_loop.h"

#include <gtest/gtest.h>
#include <pthread.h>
#include <sched.h>
#include <sys/epoll.h>
#include <sys/eventfd.h>
#include <sys/resource.h>
#include <sys/syscall.h>
#include <unistd.h>

#include <atomic>
#include <future>
#include <thread>

namespace wircam::link {
namespace {

using std::chrono::milliseconds;

TEST(EventLoop, FiresATimerOnceWhenDue) {
  EventLoop loop;
  std::atomic<int> fired{0};
  std::promise<void> done;
  auto id = loop.addTimer([&] {
    if (++fired == 1) done.set_value();
  });
  loop.arm(id, Clock::now() + milliseconds(5));
  ASSERT_EQ(done.get_future().wait_for(milliseconds(2000)), std::future_status::ready);
  loop.invoke([] {});  // the loop has gone round once more
  EXPECT_EQ(fired, 1);
  loop.remove(id);
}

TEST(EventLoop, ADisarmedTimerDoesNotFire) {
  EventLoop loop;
  std::atomic<bool> fired{false};
  auto id = loop.addTimer([&] { fired = true; });
  loop.arm(id, Clock::now() + milliseconds(20));
  loop.disarm(id);
  // A later timer firing shows the loop went past the first one's time.
  std::promise<void> later;
  loop.arm(loop.addTimer([&] { later.set_value(); }), Clock::now() + milliseconds(40));
  later.get_future().wait();
  EXPECT_FALSE(fired);
}

// A timer moved later from another thread costs the loop no wake-up, and
// a timer moved earlier still fires at its time.
TEST(EventLoop, ATimerMovedLaterFromAnotherThreadDoesNotWakeTheLoop) {
  EventLoop loop;
  std::atomic<int> fired{0};
  auto id = loop.addTimer([&] { ++fired; });
  loop.arm(id, Clock::now() + milliseconds(60));
  loop.invoke([] {});  // the loop sleeps from here
  uint64_t before = loop.wakeUps();
  for (int turn = 0; turn < 20; ++turn) {
    std::this_thread::sleep_for(milliseconds(10));
    loop.arm(id, Clock::now() + milliseconds(60));
  }
  EXPECT_EQ(loop.wakeUps(), before);
  EXPECT_EQ(fired, 0);
  std::promise<void> done;
  auto early = loop.addTimer([&] { done.set_value(); });
  auto set = Clock::now();
  loop.arm(early, set + milliseconds(20));
  ASSERT_EQ(done.get_future().wait_for(milliseconds(2000)), std::future_status::ready);
  EXPECT_GE(Clock::now() - set, milliseconds(20) - EventLoop::kCoalesce);
  loop.remove(early);
  loop.remove(id);
}

TEST(EventLoop, CallsAWatchWhenItsDescriptorIsReady) {
  EventLoop loop;
  UniqueFd fd(eventfd(0, EFD_NONBLOCK));
  std::promise<uint32_t> ready;
  auto id = loop.watch(fd.get(), EPOLLIN, [&](uint32_t events) {
    uint64_t value;
    if (read(fd.get(), &value, sizeof value) > 0) ready.set_value(events);
  });
  uint64_t one = 1;
  ASSERT_EQ(write(fd.get(), &one, sizeof one), 8);
  auto future = ready.get_future();
  ASSERT_EQ(future.wait_for(milliseconds(2000)), std::future_status::ready);
  EXPECT_TRUE(future.get() & EPOLLIN);
  loop.remove(id);
}

TEST(EventLoop, RemoveWaitsForARunningCallbackToFinish) {
  EventLoop loop;
  std::promise<void> entered;
  std::atomic<bool> finished{false};
  auto id = loop.addTimer([&] {
    entered.set_value();
    std::this_thread::sleep_for(milliseconds(50));
    finished = true;
  });
  loop.arm(id, Clock::now());
  entered.get_future().wait();
  loop.remove(id);
  EXPECT_TRUE(finished);
}

TEST(EventLoop, InvokeRunsOnTheLoopThreadAndInlineFromIt) {
  EventLoop loop;
  bool onLoop = false, nested = false;
  loop.invoke([&] {
    onLoop = loop.inLoopThread();
    loop.invoke([&] { nested = true; });
  });
  EXPECT_TRUE(onLoop);
  EXPECT_TRUE(nested);
}

TEST(EventLoop, RunsOnANamedThreadAheadOfTheVideoWhenAllowed) {
  EventLoop loop;
  char name[16] = {};
  int nice = 0, allowedNice = 0, policy = SCHED_OTHER;
  sched_param param{};
  loop.invoke([&] {
    pthread_getname_np(pthread_self(), name, sizeof name);
    nice = getpriority(PRIO_PROCESS, static_cast<id_t>(syscall(SYS_gettid)));
    pthread_getschedparam(pthread_self(), &policy, &param);
    // What this process may raise a thread to (CAP_SYS_NICE: anything).
    rlimit limit{};
    getrlimit(RLIMIT_NICE, &limit);
    allowedNice = geteuid() == 0 ? -20 : 20 - static_cast<int>(limit.rlim_cur);
  });
  EXPECT_STREQ(name, "wircam-links");
  // The lowest real-time priority; where that is refused (no RLIMIT_RTPRIO,
  // or a container's cgroup without real-time time), nice -10 if allowed.
  if (policy == SCHED_RR) {
    EXPECT_EQ(param.sched_priority, 1);
  } else if (allowedNice <= -10) {
    EXPECT_EQ(nice, -10);
  } else {
    EXPECT_EQ(nice, getpriority(PRIO_PROCESS, 0));
  }
  if (geteuid() == 0) {
    EXPECT_TRUE(policy == SCHED_RR || nice == -10) << "root may run it ahead";
  }
}

}  // namespace
}  // namespace wircam::link
