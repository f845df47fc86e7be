#include "camera/bus_watch.h"

#include <sys/eventfd.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstdint>
#include <utility>
#include <vector>

#include "common/priority_inheriting_mutex.h"

namespace wircam::recorder {

struct BusWatch::Lane {
  GstBus* bus;
  GstBusFunc handler;
  gpointer data;
  bool open = true;  // on the main loop
};

namespace {

struct Posted {
  std::shared_ptr<BusWatch::Lane> lane;
  GstMessage* message;
};

// The queue every watched bus posts into, and the one source on the
// default main context that empties it. A post into an empty queue wakes
// the loop through an eventfd, a system call that takes no lock of the
// loop's: the links' loop and the disks' writers, which run ahead of
// every other thread (thread_priority.h), post too, and GLib's own ways
// of waking a loop (g_source_set_ready_time, g_main_context_wakeup) take
// its context's lock, which the main loop's thread holds as it polls,
// and which lends no priority. (With them, a simulator twice went 800 ms
// without a keepalive under the whole suite's load, likely behind a
// preempted main thread.) The queue's own lock does lend it, and the main
// thread holds it only to take the queue.
class Hub {
 public:
  // Made at the first watch, for the rest of the process.
  static Hub& instance() {
    static Hub* hub = new Hub;
    return *hub;
  }

  // On the posting thread.
  void post(std::shared_ptr<BusWatch::Lane> lane, GstMessage* message) {
    bool wasEmpty;
    {
      MutexLock lock(mutex_);
      wasEmpty = queued_.empty();
      queued_.push_back({std::move(lane), message});
    }
    if (wasEmpty) {
      uint64_t one = 1;
      [[maybe_unused]] ssize_t written = write(wake_, &one, sizeof one);
    }
  }

  // No more posts from its bus, and none delivered of those waiting. On
  // the main loop.
  static void close(BusWatch::Lane& lane) {
    if (!lane.open) return;
    lane.open = false;
    gst_bus_set_sync_handler(lane.bus, nullptr, nullptr, nullptr);
  }

  GstMessage* take(const BusWatch::Lane& lane, GstMessageType type) {
    MutexLock lock(mutex_);
    auto found = std::find_if(queued_.begin(), queued_.end(), [&](const Posted& posted) {
      return posted.lane.get() == &lane && GST_MESSAGE_TYPE(posted.message) == type;
    });
    if (found == queued_.end()) return nullptr;
    GstMessage* message = found->message;
    queued_.erase(found);
    return message;
  }

 private:
  Hub() : wake_(eventfd(0, EFD_CLOEXEC | EFD_NONBLOCK)) {
    // Without it no camera would hear its elements: said, not limped on.
    if (wake_ < 0)
      g_error("wirc-recorder: cannot make an eventfd for the cameras' messages: %s",
              g_strerror(errno));
    static GSourceFuncs funcs = {.prepare = nullptr,
                                 .check = nullptr,
                                 .dispatch = onReady,
                                 .finalize = nullptr,
                                 .closure_callback = nullptr,
                                 .closure_marshal = nullptr};
    source_ = g_source_new(&funcs, sizeof(GSource));
    g_source_set_name(source_, "wircam camera buses");
    g_source_add_unix_fd(source_, wake_, G_IO_IN);
    // GLib 2.74 takes a source that may not recurse out of the loop's poll
    // while it dispatches it and puts it back after, and each of the two
    // wakes the loop: two more turns for every delivery. No handler runs
    // the loop (only the exit's hook drain does, after the cameras), and
    // deliver() would refuse a turn inside its own.
    g_source_set_can_recurse(source_, TRUE);
    g_source_attach(source_, nullptr);
  }

  static gboolean onReady(GSource*, GSourceFunc, gpointer) {
    instance().deliver();
    return G_SOURCE_CONTINUE;
  }

  // Everything posted until now, in order. (The wake-up is read before
  // the queue is taken: a post after that finds it empty and wakes the
  // loop again.)
  void deliver() {
    if (delivering_.size() > 0) return;  // (a turn inside a handler's)
    uint64_t posts = 0;
    [[maybe_unused]] ssize_t read = ::read(wake_, &posts, sizeof posts);
    {
      MutexLock lock(mutex_);
      std::swap(queued_, delivering_);
    }
    for (Posted& posted : delivering_) {
      BusWatch::Lane& lane = *posted.lane;
      if (lane.open && !lane.handler(lane.bus, posted.message, lane.data)) close(lane);
      gst_message_unref(posted.message);
    }
    delivering_.clear();  // (its capacity kept)
  }

  int wake_;  // an eventfd: written by a post into an empty queue
  GSource* source_;
  PriorityInheritingMutex mutex_;
  std::vector<Posted> queued_ WIRCAM_GUARDED_BY(mutex_);
  std::vector<Posted> delivering_;  // the main loop's
};

GstBusSyncReply onPosted(GstBus*, GstMessage* message, gpointer lane) {
  Hub::instance().post(*static_cast<std::shared_ptr<BusWatch::Lane>*>(lane), message);
  return GST_BUS_DROP;  // (its reference is the queue's)
}

}  // namespace

BusWatch::BusWatch(GstBus* bus, GstBusFunc handler, gpointer data)
    : lane_(
          std::make_shared<Lane>(Lane{static_cast<GstBus*>(gst_object_ref(bus)), handler, data})) {
  Hub::instance();  // attached on the main loop, before any post
  // The bus holds its own share of the lane while its handler may run.
  gst_bus_set_sync_handler(bus, onPosted, new std::shared_ptr<Lane>(lane_),
                           [](gpointer lane) { delete static_cast<std::shared_ptr<Lane>*>(lane); });
}

BusWatch::~BusWatch() {
  Hub::close(*lane_);
  gst_object_unref(lane_->bus);
}

GstMessage* BusWatch::take(GstMessageType type) { return Hub::instance().take(*lane_, type); }

}  // namespace wircam::recorder
