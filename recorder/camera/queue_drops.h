// The recording branch's queue, bounded in bytes: when a camera's file
// falls behind (a slow card, a stalled muxer) its frames wait here, and
// past the bound the newest are dropped and counted, so that the source,
// the live view and detection (hence following) never wait for the disk,
// and the memory a stalled disk takes stays bounded.
#pragma once

#include <gst/gst.h>

#include <atomic>
#include <cstdint>

namespace wircam::recorder {

class QueueDrops {
 public:
  // `queue`: a queue element with max-size-bytes set (its other limits 0).
  explicit QueueDrops(GstElement* queue);
  ~QueueDrops();
  QueueDrops(const QueueDrops&) = delete;
  QueueDrops& operator=(const QueueDrops&) = delete;

  // Frames that reached the queue (recorded or dropped), and those dropped.
  uint64_t arrived() const { return arrived_.load(std::memory_order_relaxed); }
  uint64_t dropped() const { return dropped_.load(std::memory_order_relaxed); }

 private:
  static GstPadProbeReturn onFrameIn(GstPad* pad, GstPadProbeInfo* info, gpointer self);
  static GstPadProbeReturn onQuery(GstPad* pad, GstPadProbeInfo* info, gpointer self);

  GstElement* queue_;
  GstPad* sink_;
  gulong probe_ = 0, queryProbe_ = 0;
  guint64 bound_ = 0;  // bytes
  std::atomic<uint64_t> arrived_{0}, dropped_{0};
};

}  // namespace wircam::recorder
