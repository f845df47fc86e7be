#include "camera/bus_watch.h"

#include <algorithm>
#include <utility>
#include <vector>

#include "common/mutex.h"

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
// default main context that empties it: a source with a ready time and no
// descriptor, which a post makes ready when the queue was empty.
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
    // (Thread-safe; it wakes the loop when the source is not being
    // dispatched, and a dispatch looks at the ready time again after.)
    if (wasEmpty) g_source_set_ready_time(source_, 0);
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
  Hub() {
    static GSourceFuncs funcs = {.prepare = nullptr,
                                 .check = nullptr,
                                 .dispatch = onReady,
                                 .finalize = nullptr,
                                 .closure_callback = nullptr,
                                 .closure_marshal = nullptr};
    source_ = g_source_new(&funcs, sizeof(GSource));
    g_source_set_name(source_, "wircam camera buses");
    g_source_attach(source_, nullptr);
  }

  static gboolean onReady(GSource*, GSourceFunc, gpointer) {
    instance().deliver();
    return G_SOURCE_CONTINUE;
  }

  // Everything posted until now, in order. (Not ready again until a post
  // finds the queue empty: the ready time is cleared before the queue is
  // taken, so a post after it makes the source ready again.)
  void deliver() {
    g_source_set_ready_time(source_, -1);
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

  GSource* source_;
  Mutex mutex_;
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
