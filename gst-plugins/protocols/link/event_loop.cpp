#include "link/event_loop.h"

#include <pthread.h>
#include <sys/epoll.h>
#include <sys/eventfd.h>
#include <sys/timerfd.h>
#include <unistd.h>

#include <array>
#include <future>
#include <mutex>
#include <vector>

#include "common/thread_priority.h"

namespace wircam::link {

EventLoop& EventLoop::shared() {
  static auto* loop = new EventLoop();
  return *loop;
}

namespace {
// The epoll data of the loop's own descriptors; entries' ids start at 1.
constexpr uint64_t kWakeData = 0;
constexpr uint64_t kAlarmData = ~uint64_t{0};
}  // namespace

EventLoop::EventLoop()
    : epoll_(epoll_create1(EPOLL_CLOEXEC)),
      wake_(eventfd(0, EFD_CLOEXEC | EFD_NONBLOCK)),
      alarm_(timerfd_create(CLOCK_MONOTONIC, TFD_CLOEXEC | TFD_NONBLOCK)) {
  epoll_event wake{.events = EPOLLIN, .data = {.u64 = kWakeData}};
  epoll_ctl(epoll_.get(), EPOLL_CTL_ADD, wake_.get(), &wake);
  epoll_event alarm{.events = EPOLLIN, .data = {.u64 = kAlarmData}};
  epoll_ctl(epoll_.get(), EPOLL_CTL_ADD, alarm_.get(), &alarm);
  thread_ = std::thread([this] { run(); });
}

EventLoop::~EventLoop() {
  {
    MutexLock lock(mutex_);
    stopping_ = true;
  }
  wake();
  thread_.join();
}

void EventLoop::wake() {
  uint64_t one = 1;
  if (write(wake_.get(), &one, sizeof one) < 0) {
    // Only fails when the counter is saturated: the loop is awake anyway.
  }
}

EventLoop::Id EventLoop::watch(int fd, uint32_t events, IoCallback callback) {
  MutexLock lock(mutex_);
  Id id = nextId_++;
  entries_[id] = Entry{.fd = fd, .onIo = std::make_shared<const IoCallback>(std::move(callback))};
  epoll_event event{.events = events, .data = {.u64 = id}};
  epoll_ctl(epoll_.get(), EPOLL_CTL_ADD, fd, &event);
  return id;
}

void EventLoop::setEvents(Id id, uint32_t events) {
  MutexLock lock(mutex_);
  auto it = entries_.find(id);
  if (it == entries_.end()) return;
  epoll_event event{.events = events, .data = {.u64 = id}};
  epoll_ctl(epoll_.get(), EPOLL_CTL_MOD, it->second.fd, &event);
}

EventLoop::Id EventLoop::addTimer(Callback callback) {
  MutexLock lock(mutex_);
  Id id = nextId_++;
  entries_[id] = Entry{.onTimer = std::make_shared<const Callback>(std::move(callback))};
  return id;
}

void EventLoop::arm(Id id, Clock::time_point when) {
  MutexLock lock(mutex_);
  auto it = entries_.find(id);
  if (it == entries_.end()) return;
  Entry& entry = it->second;
  unqueue(entry);
  if (entry.spare) {
    entry.spare.key() = when;
    entry.queued = timers_.insert(std::move(entry.spare));
  } else {
    entry.queued = timers_.emplace(when, id);  // its first arm
  }
  followEarliestTimer();
}

void EventLoop::disarm(Id id) {
  MutexLock lock(mutex_);
  auto it = entries_.find(id);
  if (it == entries_.end()) return;
  unqueue(it->second);
  followEarliestTimer();
}

void EventLoop::unqueue(Entry& entry) {
  if (!entry.queued) return;
  entry.spare = timers_.extract(*entry.queued);
  entry.queued.reset();
}

void EventLoop::followEarliestTimer() {
  std::optional<Clock::time_point> earliest;
  if (!timers_.empty()) earliest = timers_.begin()->first;
  if (earliest == alarmTime_) return;
  alarmTime_ = earliest;
  itimerspec due{};  // all zero: disarmed
  if (earliest) {
    // steady_clock is CLOCK_MONOTONIC. A time in the past (invoke() arms
    // at time_point::min()) fires at once; zero would disarm.
    auto ns = std::max<int64_t>(
        1,
        std::chrono::duration_cast<std::chrono::nanoseconds>(earliest->time_since_epoch()).count());
    due.it_value = {.tv_sec = ns / 1000000000, .tv_nsec = ns % 1000000000};
  }
  timerfd_settime(alarm_.get(), TFD_TIMER_ABSTIME, &due, nullptr);
}

void EventLoop::waitUntilIdle(Id id) {
  if (inLoopThread()) return;
  idle_.wait(mutex_, [&]() WIRCAM_REQUIRES(mutex_) { return running_ != id; });
}

void EventLoop::remove(Id id) {
  MutexLock lock(mutex_);
  auto it = entries_.find(id);
  if (it == entries_.end()) return;
  if (it->second.fd >= 0) epoll_ctl(epoll_.get(), EPOLL_CTL_DEL, it->second.fd, nullptr);
  unqueue(it->second);
  followEarliestTimer();
  // Destroyed here, outside the lock, once the loop has let go of it.
  Entry entry = std::move(it->second);
  entries_.erase(it);
  waitUntilIdle(id);
  lock.unlock();
}

void EventLoop::invoke(const Callback& task) {
  if (inLoopThread()) {
    task();
    return;
  }
  std::promise<void> done;
  Id timer = addTimer([&] {
    task();
    done.set_value();
  });
  arm(timer, Clock::time_point::min());
  done.get_future().wait();
  remove(timer);
}

// The loop feeds the vehicles' watchdogs (the WiRC drops a transmitter
// whose PCD stop for 800 ms): on processors busy with video it must not
// queue behind the streaming threads.
void EventLoop::run() {
  pthread_setname_np(pthread_self(), "wircam-links");
  runThisThreadAhead();
  std::array<epoll_event, 64> events;
  std::vector<Id> due;
  for (;;) {
    {
      MutexLock lock(mutex_);
      if (stopping_) return;
    }
    int count = epoll_wait(epoll_.get(), events.data(), static_cast<int>(events.size()), -1);
    ++wakeUps_;

    // Each callback runs with running_ set, so remove() can wait for it.
    auto runEntry = [&](Id id, uint32_t ready) {
      std::shared_ptr<const Callback> onTimer;
      std::shared_ptr<const IoCallback> onIo;
      {
        MutexLock lock(mutex_);
        auto it = entries_.find(id);
        if (it == entries_.end()) return;
        if (ready == 0)
          onTimer = it->second.onTimer;
        else
          onIo = it->second.onIo;
        running_ = id;
      }
      if (onIo) (*onIo)(ready);
      if (onTimer) (*onTimer)();
      {
        MutexLock lock(mutex_);
        running_ = 0;
      }
      idle_.notifyAll();
    };

    for (int i = 0; i < count; ++i) {
      uint64_t data = events[i].data.u64;
      if (data == kWakeData || data == kAlarmData) {
        uint64_t value;
        if (read(data == kWakeData ? wake_.get() : alarm_.get(), &value, sizeof value) < 0) {
          // Spurious: nothing to drain.
        }
        if (data == kAlarmData) {
          MutexLock lock(mutex_);
          alarmTime_.reset();  // spent: set again below
        }
        continue;
      }
      runEntry(data, events[i].events);
    }

    due.clear();
    {
      MutexLock lock(mutex_);
      auto horizon = Clock::now() + kCoalesce;
      while (!timers_.empty() && timers_.begin()->first <= horizon) {
        Id id = timers_.begin()->second;
        Entry& entry = entries_[id];
        entry.queued.reset();
        entry.spare = timers_.extract(timers_.begin());
        due.push_back(id);
      }
      followEarliestTimer();
    }
    for (Id id : due) runEntry(id, 0);
  }
}

}  // namespace wircam::link
