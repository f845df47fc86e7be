// A camera's bus, watched from the main loop through one source that all
// cameras share. A bus watch of its own (gst_bus_add_watch) puts a
// descriptor and a source on the main loop for each camera, and every turn
// of the loop prepares, polls and checks them all: at 256 cameras, whose
// statistics come once a second each, the loop turned about 270 times a
// second over 256 of them. Here each bus hands its messages over on the
// thread that posts them (a sync handler), into one queue, and the loop's
// one source (one descriptor, woken by a post into the empty queue)
// delivers all that waits in a single turn.
#pragma once

#include <gst/gst.h>

#include <memory>

namespace wircam::recorder {

class BusWatch {
 public:
  // Delivers what `bus` posts from now on to `handler`, in the order
  // posted, on the default main context; until `handler` returns FALSE or
  // the watch is destroyed. (The bus keeps no message: gst_bus_pop finds
  // none; take() does.) On the main loop.
  BusWatch(GstBus* bus, GstBusFunc handler, gpointer data);
  // No message is delivered after, even one already posted; may run inside
  // `handler`. On the main loop.
  ~BusWatch();
  BusWatch(const BusWatch&) = delete;
  BusWatch& operator=(const BusWatch&) = delete;

  // The first message of `type` posted and not delivered yet, taken out
  // of the queue (the caller unrefs it); or null. For what a call on the
  // main loop posted itself (a state change that failed says why).
  GstMessage* take(GstMessageType type);

  struct Lane;  // (bus_watch.cpp)

 private:
  std::shared_ptr<Lane> lane_;
};

}  // namespace wircam::recorder
