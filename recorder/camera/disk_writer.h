// Writes the recorded files of every camera on one filesystem from one
// thread (one per st_dev, shared while used): a camera's muxer hands its
// bytes over on the camera's own thread and goes on, so a slow or stalled
// disk holds up the cameras writing to it only through their DiskBudget
// (past it their frames are dropped and counted), never their threads, and
// a camera costs no thread of its own for its files.
#pragma once

#include <gst/gst.h>
#include <sys/uio.h>

#include <atomic>
#include <cstdint>
#include <functional>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "common/expected.h"
#include "common/priority_inheriting_mutex.h"

namespace wircam::recorder {

// How much of one camera's video may wait for its disk, in bytes; what
// came and what was dropped past it. Shared by the camera's files and the
// writes in flight (any thread). It also takes the written bytes back
// from the writer, for the camera's thread to free: the writer frees
// nothing (see DiskWriter).
class DiskBudget {
 public:
  explicit DiskBudget(uint64_t bound);
  ~DiskBudget();
  DiskBudget(const DiskBudget&) = delete;
  DiskBudget& operator=(const DiskBudget&) = delete;
  bool full() const { return waiting_.load(std::memory_order_relaxed) >= bound_; }
  uint64_t waiting() const { return waiting_.load(std::memory_order_relaxed); }
  void handedOver(uint64_t bytes) { waiting_.fetch_add(bytes, std::memory_order_relaxed); }
  void written(uint64_t bytes) { waiting_.fetch_sub(bytes, std::memory_order_relaxed); }

  // Frames that came for the files (recorded or dropped), and those dropped.
  void countArrival() { arrived_.fetch_add(1, std::memory_order_relaxed); }
  void countDrop() { dropped_.fetch_add(1, std::memory_order_relaxed); }
  uint64_t framesArrived() const { return arrived_.load(std::memory_order_relaxed); }
  uint64_t framesDropped() const { return dropped_.load(std::memory_order_relaxed); }

  // `bytes` are written (the writer's thread); they wait to be freed.
  void giveBack(GstBuffer* bytes);
  // Frees what was given back (the camera's thread, at its next hand-over;
  // nothing if another of its threads is at it).
  void freeGivenBack();

 private:
  const uint64_t bound_;
  std::atomic<uint64_t> waiting_{0}, arrived_{0}, dropped_{0};
  PriorityInheritingMutex givenBackMutex_;  // shared with the writer
  std::vector<GstBuffer*> givenBack_ WIRCAM_GUARDED_BY(givenBackMutex_);
  // The camera's side (two of its files may hand over on two threads);
  // kept for its capacity. Never taken by the writer.
  std::mutex freeingMutex_;
  std::vector<GstBuffer*> freeing_;
};

// The writer runs ahead of the video threads (thread_priority.h), and so
// must never wait for one: it shares only priority-inheriting locks with
// them, and calls neither malloc nor free in its loop, whose locks (an
// arena's, shared by dozens of threads) it would otherwise wait on behind
// a preempted video thread. (Seen at 256 cameras on saturated processors:
// nearly every time the writer slept, it slept in malloc's lock, and the
// cameras' bounds filled.) So its lists keep their capacity, and it gives
// the written bytes back to each camera's DiskBudget to free.
class DiskWriter {
 public:
  // A file open for writing: its descriptor, the writes still waiting, and
  // the first error a write met (errno; 0: none).
  class File;

  // The writer of the filesystem `folder` is on: made at the first use,
  // shared while any camera holds it.
  static Expected<std::shared_ptr<DiskWriter>, std::string> of(const std::string& folder);
  ~DiskWriter();  // after what was handed over is written
  DiskWriter(const DiskWriter&) = delete;
  DiskWriter& operator=(const DiskWriter&) = delete;

  // `path`, created or emptied, on the caller's thread; or why not (errno).
  static Expected<std::shared_ptr<File>, int> open(const std::string& path);
  // `bytes` (a reference is taken) at `offset` of `file`, on the writer's
  // thread, in the order handed over; counted in `budget` until written.
  void write(const std::shared_ptr<File>& file, uint64_t offset, GstBuffer* bytes,
             const std::shared_ptr<DiskBudget>& budget);
  // Waits until every write handed over for `file` is done, then closes
  // it. Returns the first error its writes met (errno; 0: none).
  int close(const std::shared_ptr<File>& file);
  // Closes `file` once every write handed over for it is done, without
  // waiting for it: `closed` then runs, on the writer's thread (or on the
  // caller's, when nothing waits), with the first error its writes met.
  void closeWhenWritten(const std::shared_ptr<File>& file, std::function<void(int error)> closed);
  // The error `file`'s writes have met so far (0: none), any thread.
  static int errorOf(const File& file);
  // Waits until every writer has written all that was handed to it: before
  // the process exits, which would lose what a writer still holds (a file
  // cut off at the stop lets its writes go on without anyone waiting).
  static void finishAll();

  // A disk that stops taking data, for tests: the thread writes nothing
  // from hold() until release().
  void hold();
  void release();

 private:
  explicit DiskWriter(dev_t device);
  struct Write {
    std::shared_ptr<File> file;
    uint64_t offset;
    GstBuffer* bytes;
    std::shared_ptr<DiskBudget> budget;
  };
  void run();
  // With mutex_ held: the thread writes at once, without gathering, until
  // `done()` (close(), finishAll()).
  template <class Done>
  void writeNowUntil(Done done) WIRCAM_REQUIRES(mutex_);
  // Writes batch_[first] and the writes after it that continue it in its
  // file; returns how many.
  size_t performRun(size_t first);
  static void writeAll(File& file, std::vector<iovec>& pieces, uint64_t offset);

  const dev_t device_;
  // Guards writes_, ending_, idle_ and each File's count of writes waiting.
  PriorityInheritingMutex mutex_;
  PriorityInheritingCondition wake_;  // writes to do, or the end
  PriorityInheritingCondition done_;  // a file's writes are all done
  std::vector<Write> writes_ WIRCAM_GUARDED_BY(mutex_);
  // The writer's own (the batch being written, a run's pieces), kept for
  // their capacity.
  std::vector<Write> batch_;
  std::vector<GstMapInfo> maps_;
  std::vector<iovec> pieces_;
  uint64_t bytesWaiting_ WIRCAM_GUARDED_BY(mutex_) = 0;
  int closing_ WIRCAM_GUARDED_BY(mutex_) = 0;  // callers of writeNowUntil(): no gathering then
  bool writing_ WIRCAM_GUARDED_BY(mutex_) =
      false;  // a batch taken from writes_, and its files' ends
  bool held_ WIRCAM_GUARDED_BY(mutex_) = false;
  bool ending_ WIRCAM_GUARDED_BY(mutex_) = false;
  std::thread thread_;
};

// Where a camera's files go: handed to its filesystem's writer within its
// budget; without a writer, through a filesink on the camera's own thread.
struct CameraDisk {
  std::shared_ptr<DiskWriter> writer;
  std::shared_ptr<DiskBudget> budget;
};

}  // namespace wircam::recorder
