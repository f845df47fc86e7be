// Writes the recorded files of every camera on one filesystem from one
// thread (one per st_dev, made at its first use, for the rest of the
// process; it sleeps while nothing is handed over): a camera's muxer hands its
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

#include "camera/disk_budget.h"
#include "common/expected.h"
#include "common/priority_inheriting_mutex.h"

namespace wircam::recorder {

// The writer runs ahead of the video threads (thread_priority.h), and so
// must never wait for one: it shares only priority-inheriting locks with
// them, and calls neither malloc nor free in its loop, whose locks (an
// arena's, shared by dozens of threads) it would otherwise wait on behind
// a preempted video thread. (Seen at 256 cameras on saturated processors:
// nearly every time the writer slept, it slept in malloc's lock, and the
// cameras' bounds filled.) So its lists keep their capacity, and it gives
// the written bytes back to each camera's DiskBudget to free. Nor does a
// camera's hand-over lock anything another camera locks: each camera has
// its lane (disk_budget.h), and the lanes with writes wait on a list that
// takes no lock.
class DiskWriter {
 public:
  // A file open for writing: its descriptor, the writes still waiting, and
  // the first error a write met (errno; 0: none).
  using File = DiskFile;

  // The writer of the filesystem `folder` is on: made at the first use,
  // kept for the rest of the process.
  static Expected<std::shared_ptr<DiskWriter>, std::string> of(const std::string& folder);
  ~DiskWriter();  // after what was handed over is written (the registry's never is)
  DiskWriter(const DiskWriter&) = delete;
  DiskWriter& operator=(const DiskWriter&) = delete;

  // `path`, created or emptied, on the caller's thread; or why not (errno).
  static Expected<std::shared_ptr<File>, int> open(const std::string& path);
  // `bytes` (a reference is taken) at `offset` of `file`, on the writer's
  // thread, in the order handed over; counted in `budget` (the camera's
  // lane to this writer) until written.
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
  DiskWriter();
  void run();
  // Puts `lane` on the list of lanes with writes; true when it was empty.
  bool list(DiskBudget* lane);
  bool anyListed() const { return listed_.load(std::memory_order_acquire) != nullptr; }
  // The lanes taken off the list (newest first, as pushed), oldest first:
  // what waits longest goes first, and a lane listed after another is
  // written after it, so a write that lists its lane waits for every write
  // handed over before it.
  static DiskBudget* inListedOrder(DiskBudget* newestFirst);
  // Wakes the thread (after a change to what its waits read).
  void wake();
  // Writes what `lane` holds: taken into batch_, written, given back.
  void writeLane(DiskBudget& lane);
  // With mutex_ held: the thread writes at once, without gathering, until
  // `done()` (close(), finishAll()).
  template <class Done>
  void writeNowUntil(Done done) WIRCAM_REQUIRES(mutex_);
  // Writes batch_[first] and the writes after it that continue it in its
  // file; returns how many.
  size_t performRun(size_t first);
  // With batch_ written: its files' counts of writes waiting, and the ends
  // of those closed when written.
  void countWritten();
  static void writeAll(File& file, std::vector<iovec>& pieces, uint64_t offset);

  // The lanes with writes, linked through DiskBudget::nextListed_: pushed
  // by the cameras, taken all at once by the thread.
  std::atomic<DiskBudget*> listed_{nullptr};
  std::atomic<uint64_t> bytesWaiting_{0};  // handed over since the pass began
  // Guards the marked fields and the decrease of each File's count of
  // writes waiting (its end waits on it). No camera takes it to hand over,
  // only to wake the thread.
  PriorityInheritingMutex mutex_;
  PriorityInheritingCondition wake_;  // writes to do, or the end
  PriorityInheritingCondition done_;  // a file's writes are all done
  // The writer's own (a lane's writes being written, a run's pieces), kept
  // for their capacity.
  std::vector<DiskWrite> batch_;
  std::vector<GstMapInfo> maps_;
  std::vector<iovec> pieces_;
  int closing_ WIRCAM_GUARDED_BY(mutex_) = 0;       // callers of writeNowUntil(): no gathering then
  bool writing_ WIRCAM_GUARDED_BY(mutex_) = false;  // lanes taken, not all written
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
