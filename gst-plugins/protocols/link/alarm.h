// A timer of one link's own: a timerfd the event loop watches, so that a
// stream's thread can move it (a keepalive sent on a frame's turn, ten
// times a second a link) with one system call and no lock shared with the
// other links. Moved on the loop's own timers, every keepalive took the
// loop's lock, on which hundreds of cameras' threads and the loop itself
// then queued (docs/performance.md, "The cameras queued on the links'
// lock").
//
// Alarms still share wake-ups: given a window, an alarm goes off at the
// first tick in it of a grid every alarm shares (EventLoop::kCoalesce
// apart), so links whose keepalives fall due about the same time expire
// together and one epoll_wait returns them all.
#pragma once

#include "common/socket.h"
#include "link/command_pacer.h"
#include "link/event_loop.h"

namespace wircam::link {

class Alarm {
 public:
  Alarm(EventLoop& loop, EventLoop::Callback onAlarm);
  ~Alarm();
  Alarm(const Alarm&) = delete;
  Alarm& operator=(const Alarm&) = delete;

  // Goes off once, not before `earliest`: at the grid's first tick from
  // there, or at `latest` when that comes first. Setting it again moves
  // it, from any thread; callers on several threads order their sets (a
  // link's lock), as the last set wins.
  void set(Clock::time_point earliest, Clock::time_point latest);
  void set(Clock::time_point when) { set(when, when); }
  // When a pacer has something to send next. Every link (WiRC, RCOIP,
  // BTEMP) sends its commands the same way: under its lock, ask its pacer
  // and set its alarm by it; outside the lock, send.
  void set(const CommandPacer::Window& window) { set(window.earliest, window.latest); }

  // Once it returns, the callback does not run again (unless called from
  // the callback itself). Also done by the destructor.
  void stop();

  // The time set() goes off at (for tests).
  static Clock::time_point dueTime(Clock::time_point earliest, Clock::time_point latest);

 private:
  void onReadable();

  EventLoop& loop_;
  UniqueFd timer_;
  EventLoop::Callback onAlarm_;
  EventLoop::Id watch_ = 0;
};

}  // namespace wircam::link
