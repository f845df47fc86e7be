// One camera's lane to its filesystem's writer (disk_writer.h): how much
// of its video may wait for the disk, in bytes; the writes waiting, in the
// order handed over; and the written bytes coming back, for the camera's
// thread to free.
//
// Each camera has a lane of its own so that handing a write over locks
// nothing another camera locks. With one list for every camera, 256
// cameras on saturated processors queued on its lock: a lock that lends
// priority hands itself to the next waiter, which then holds it until the
// scheduler runs it, and sampled, nearly every camera thread sat in that
// queue instead of reading its socket (docs/performance.md).
#pragma once

#include <gst/gst.h>

#include <atomic>
#include <cstdint>
#include <memory>
#include <mutex>
#include <vector>

#include "common/priority_inheriting_mutex.h"

namespace wircam::recorder {

class DiskWriter;
class DiskFile;

// `bytes` (a reference held) at `offset` of `file`.
struct DiskWrite {
  std::shared_ptr<DiskFile> file;
  uint64_t offset;
  GstBuffer* bytes;
};

// Shared by the camera's files and the writes in flight (any thread). A
// lane's writes go to one writer.
class DiskBudget {
 public:
  explicit DiskBudget(uint64_t bound);
  ~DiskBudget();
  DiskBudget(const DiskBudget&) = delete;
  DiskBudget& operator=(const DiskBudget&) = delete;
  bool full() const { return waiting_.load(std::memory_order_relaxed) >= bound_; }
  uint64_t waiting() const { return waiting_.load(std::memory_order_relaxed); }

  // Frames that came for the files (recorded or dropped), and those dropped.
  void countArrival() { arrived_.fetch_add(1, std::memory_order_relaxed); }
  void countDrop() { dropped_.fetch_add(1, std::memory_order_relaxed); }
  uint64_t framesArrived() const { return arrived_.load(std::memory_order_relaxed); }
  uint64_t framesDropped() const { return dropped_.load(std::memory_order_relaxed); }

 private:
  friend class DiskWriter;
  // The camera's side: queues `write` (its bytes counted until written)
  // and frees what the writer gave back since (unless another of the
  // camera's threads is at it), under one lock; true when the lane was not
  // on its writer's list of lanes with writes, and so is to be put there.
  bool queue(DiskWrite&& write, const std::shared_ptr<DiskBudget>& self);
  // The writer's side: takes the waiting writes into `into` (empty; the
  // lane keeps its capacity) and what keeps the lane alive meanwhile.
  std::shared_ptr<DiskBudget> take(std::vector<DiskWrite>& into);
  // `written` are on disk (or failed): their bytes are given back, not freed.
  void giveBack(const std::vector<DiskWrite>& written);

  const uint64_t bound_;
  std::atomic<uint64_t> waiting_{0}, arrived_{0}, dropped_{0};
  // Shared with the writer only, which never waits on a lock another
  // camera takes.
  PriorityInheritingMutex laneMutex_;
  std::vector<DiskWrite> writes_ WIRCAM_GUARDED_BY(laneMutex_);
  // On the writer's list, kept alive by itself until the writer takes it.
  std::shared_ptr<DiskBudget> listed_ WIRCAM_GUARDED_BY(laneMutex_);
  std::vector<GstBuffer*> givenBack_ WIRCAM_GUARDED_BY(laneMutex_);
  // The writer's list's link, set before the lane is put there.
  DiskBudget* nextListed_ = nullptr;
  // The camera's side (two of its files may hand over on two threads);
  // kept for its capacity. Never taken by the writer.
  std::mutex freeingMutex_;
  std::vector<GstBuffer*> freeing_;
};

}  // namespace wircam::recorder
