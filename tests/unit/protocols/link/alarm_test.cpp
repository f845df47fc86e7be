// A link's own alarm on the event loop: when it goes off, and that moving
// it costs the loop nothing.
#include "link/alarm.h"

#include <gtest/gtest.h>

#include <atomic>
#include <future>
#include <thread>

namespace wircam::link {
namespace {

using std::chrono::milliseconds;

Clock::time_point onGrid(int64_t ticks) {
  return Clock::time_point(ticks *
                           std::chrono::duration_cast<Clock::duration>(EventLoop::kCoalesce));
}

TEST(Alarm, GoesOffAtTheGridsFirstTickInItsWindowOrAtItsEnd) {
  auto tick = onGrid(1000);
  EXPECT_EQ(Alarm::dueTime(tick - milliseconds(9), tick + milliseconds(1)), tick);
  EXPECT_EQ(Alarm::dueTime(tick, tick + milliseconds(5)), tick);
  // No tick in the window: its end, never before its start.
  EXPECT_EQ(Alarm::dueTime(tick + milliseconds(2), tick + milliseconds(4)), tick + milliseconds(4));
  EXPECT_EQ(Alarm::dueTime(tick + milliseconds(3), tick + milliseconds(3)), tick + milliseconds(3));
}

TEST(Alarm, GoesOffOnceNotBeforeItsTime) {
  EventLoop loop;
  std::atomic<int> fired{0};
  std::promise<Clock::time_point> done;
  Alarm alarm(loop, [&] {
    if (++fired == 1) done.set_value(Clock::now());
  });
  auto set = Clock::now();
  alarm.set(set + milliseconds(20));
  auto future = done.get_future();
  ASSERT_EQ(future.wait_for(milliseconds(2000)), std::future_status::ready);
  EXPECT_GE(future.get() - set, milliseconds(20));
  loop.invoke([] {});  // the loop has gone round once more
  EXPECT_EQ(fired, 1);
}

// What lets a stream's thread send a keepalive on its own turn: moving the
// link's alarm later costs the loop no wake-up.
TEST(Alarm, MovedLaterFromAnotherThreadItNeitherWakesTheLoopNorGoesOff) {
  EventLoop loop;
  std::atomic<int> fired{0};
  Alarm alarm(loop, [&] { ++fired; });
  // Each move 200 ms ahead: a busy machine may hold this thread back for
  // tens of milliseconds between two.
  alarm.set(Clock::now() + milliseconds(200));
  loop.invoke([] {});  // the loop sleeps from here
  uint64_t before = loop.wakeUps();
  for (int turn = 0; turn < 20; ++turn) {
    std::this_thread::sleep_for(milliseconds(10));
    alarm.set(Clock::now() + milliseconds(200));
  }
  EXPECT_EQ(loop.wakeUps(), before);
  EXPECT_EQ(fired, 0);
}

// Keepalives of many links due within one grid step of each other expire
// together: the loop wakes once for all of them (twice at most, should the
// kernel take two processors' timer interrupts for them), not once each.
TEST(Alarm, AlarmsWhoseWindowsShareATickShareTheLoopsWakeUp) {
  EventLoop loop;
  constexpr int kLinks = 8;
  std::atomic<int> fired{0};
  std::promise<void> all;
  std::vector<std::unique_ptr<Alarm>> alarms;
  for (int i = 0; i < kLinks; ++i)
    alarms.push_back(std::make_unique<Alarm>(loop, [&] {
      if (++fired == kLinks) all.set_value();
    }));
  loop.invoke([] {});
  uint64_t before = loop.wakeUps();
  auto tick = Alarm::dueTime(Clock::now() + milliseconds(50), Clock::time_point::max());
  for (int i = 1; i <= kLinks; ++i) {
    auto due = tick + milliseconds(i);  // each due a millisecond after the last
    alarms[i - 1]->set(due - EventLoop::kCoalesce, due);
  }
  ASSERT_EQ(all.get_future().wait_for(milliseconds(2000)), std::future_status::ready);
  EXPECT_LE(loop.wakeUps() - before, 2u);
}

TEST(Alarm, AStoppedAlarmNeverGoesOff) {
  EventLoop loop;
  std::atomic<bool> fired{false};
  Alarm alarm(loop, [&] { fired = true; });
  alarm.set(Clock::now() + milliseconds(10));
  alarm.stop();
  std::this_thread::sleep_for(milliseconds(30));
  loop.invoke([] {});
  EXPECT_FALSE(fired);
}

}  // namespace
}  // namespace wircam::link
