#include "camera/disk_writer.h"

#include <fcntl.h>
#include <pthread.h>
#include <sys/stat.h>
#include <sys/uio.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <map>
#include <mutex>
#include <utility>

#include "common/thread_priority.h"

namespace wircam::recorder {

namespace {

// The thread gathers writes for up to kGather once woken (by the first
// write after a pause), or until kGatherBytes wait, and writes them in one
// go: at 256 cameras a wake-up per 20 ms instead of one per frame a camera.
// 20 ms of video is what a crash can lose beyond what the muxer holds.
constexpr auto kGather = std::chrono::milliseconds(20);
constexpr uint64_t kGatherBytes = 1 << 20;
// Writes of one file that follow each other on it go out in one call.
constexpr size_t kMaxRun = 64;

// Each writer made, for the rest of the process. (Held by its cameras
// alone, its last holder could be its own thread: a file whose camera's
// pipeline is gone ends there, and the sink it lets go of held the
// writer; a thread cannot join itself.)
std::mutex registryMutex;
std::map<dev_t, std::shared_ptr<DiskWriter>>& registry() {
  static auto* writers = new std::map<dev_t, std::shared_ptr<DiskWriter>>;
  return *writers;
}

}  // namespace

class DiskFile {
 public:
  explicit DiskFile(int fd) : fd_(fd) {}
  ~DiskFile() {
    if (fd_ >= 0) ::close(fd_);
  }
  DiskFile(const DiskFile&) = delete;
  DiskFile& operator=(const DiskFile&) = delete;

 private:
  friend class DiskWriter;
  // Closes the descriptor; the first error its writes or its close met.
  int closeNow() {
    if (fd_ >= 0 && ::close(fd_) != 0 && error_ == 0) error_ = errno;
    fd_ = -1;
    return error_;
  }

  int fd_;
  // Writes handed over, not done: raised by the camera, lowered by the
  // writer under its mutex_ (as closeWhenWritten() reads it).
  std::atomic<int> waiting_{0};
  std::function<void(int)> closeWhenWritten_;  // (the writer's mutex_)
  std::atomic<int> error_{0};
};

Expected<std::shared_ptr<DiskWriter>, std::string> DiskWriter::of(const std::string& folder) {
  struct stat info {};
  if (stat(folder.c_str(), &info) != 0)
    return unexpected("cannot write into " + folder + ": " + std::strerror(errno));
  std::lock_guard lock(registryMutex);
  auto& known = registry()[info.st_dev];
  if (!known) known.reset(new DiskWriter);
  return known;
}

DiskWriter::DiskWriter() {
  maps_.resize(kMaxRun);
  pieces_.reserve(kMaxRun);
  thread_ = std::thread([this] { run(); });
}

DiskWriter::~DiskWriter() {
  {
    MutexLock lock(mutex_);
    ending_ = true;
  }
  wake_.notifyOne();
  thread_.join();
}

Expected<std::shared_ptr<DiskWriter::File>, int> DiskWriter::open(const std::string& path) {
  int fd = ::open(path.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (fd < 0) return unexpected(errno);
  return std::make_shared<File>(fd);
}

void DiskWriter::write(const std::shared_ptr<File>& file, uint64_t offset, GstBuffer* bytes,
                       const std::shared_ptr<DiskBudget>& budget) {
  uint64_t size = gst_buffer_get_size(bytes);
  file->waiting_.fetch_add(1, std::memory_order_relaxed);
  bool wakeUp = false;
  if (budget->queue({file, offset, gst_buffer_ref(bytes)}, budget)) wakeUp = list(budget.get());
  uint64_t before = bytesWaiting_.fetch_add(size, std::memory_order_relaxed);
  if (before < kGatherBytes && before + size >= kGatherBytes) wakeUp = true;
  if (wakeUp) wake();
}

bool DiskWriter::list(DiskBudget* lane) {
  DiskBudget* head = listed_.load(std::memory_order_relaxed);
  do {
    lane->nextListed_ = head;
  } while (!listed_.compare_exchange_weak(head, lane, std::memory_order_release,
                                          std::memory_order_relaxed));
  return head == nullptr;
}

void DiskWriter::wake() {
  // Through the mutex: the thread either has not yet read what changed,
  // or already waits and hears this.
  { MutexLock lock(mutex_); }
  wake_.notifyOne();
}

template <class Done>
void DiskWriter::writeNowUntil(Done done) {
  ++closing_;
  wake_.notifyOne();
  done_.wait(mutex_, done);
  --closing_;
}

int DiskWriter::close(const std::shared_ptr<File>& file) {
  MutexLock lock(mutex_);
  writeNowUntil([&] { return file->waiting_ == 0; });
  return file->closeNow();
}

void DiskWriter::closeWhenWritten(const std::shared_ptr<File>& file,
                                  std::function<void(int error)> closed) {
  {
    MutexLock lock(mutex_);
    if (file->waiting_ > 0) {
      file->closeWhenWritten_ = std::move(closed);
      return;
    }
  }
  closed(file->closeNow());
}

int DiskWriter::errorOf(const File& file) { return file.error_; }

void DiskWriter::finishAll() {
  std::vector<std::shared_ptr<DiskWriter>> writers;
  {
    std::lock_guard lock(registryMutex);
    for (const auto& [device, writer] : registry()) writers.push_back(writer);
  }
  for (const auto& writer : writers) {
    MutexLock lock(writer->mutex_);
    writer->writeNowUntil([&]() WIRCAM_REQUIRES(writer->mutex_) {
      return !writer->anyListed() && !writer->writing_;
    });
  }
}

void DiskWriter::hold() {
  MutexLock lock(mutex_);
  held_ = true;
}

void DiskWriter::release() {
  {
    MutexLock lock(mutex_);
    held_ = false;
  }
  wake_.notifyOne();
}

void DiskWriter::run() {
  pthread_setname_np(pthread_self(), "wircam-disk");
  // One thread writes what a thread a camera wrote before: on processors
  // busy with video, at an equal share, it would fall behind the cameras
  // (their bounds fill, then their frames drop).
  runThisThreadAhead();
  MutexLock lock(mutex_);
  while (true) {
    wake_.wait(mutex_,
               [&]() WIRCAM_REQUIRES(mutex_) { return (ending_ || anyListed()) && !held_; });
    if (!anyListed()) return;  // ending, all written
    wake_.waitFor(mutex_, kGather, [&]() WIRCAM_REQUIRES(mutex_) {
      return ending_ || closing_ > 0 ||
             bytesWaiting_.load(std::memory_order_relaxed) >= kGatherBytes;
    });
    writing_ = true;
    lock.unlock();
    bytesWaiting_.store(0, std::memory_order_relaxed);
    // (A lane's link is read before the lane is taken: once taken, its
    // camera may list it again.)
    for (DiskBudget* lane = inListedOrder(listed_.exchange(nullptr, std::memory_order_acquire));
         lane;) {
      DiskBudget* next = lane->nextListed_;
      writeLane(*lane);
      lane = next;
    }
    lock.lock();
    // The pass is over, its files' ends too: finishAll() may return.
    writing_ = false;
    done_.notifyAll();
  }
}

DiskBudget* DiskWriter::inListedOrder(DiskBudget* newestFirst) {
  // (Its lanes are still listed, so no camera touches their links.)
  DiskBudget* oldestFirst = nullptr;
  while (newestFirst) {
    DiskBudget* next = newestFirst->nextListed_;
    newestFirst->nextListed_ = oldestFirst;
    oldestFirst = std::exchange(newestFirst, next);
  }
  return oldestFirst;
}

void DiskWriter::writeLane(DiskBudget& lane) {
  std::shared_ptr<DiskBudget> kept = lane.take(batch_);
  for (size_t i = 0; i < batch_.size();) i += performRun(i);
  lane.giveBack(batch_);
  countWritten();
  batch_.clear();
  // (The last hold on a camera's lane, once it is gone, frees it: once a
  // camera.)
}

void DiskWriter::countWritten() {
  std::vector<std::pair<std::shared_ptr<File>, std::function<void(int)>>> ended;
  {
    MutexLock lock(mutex_);
    for (const DiskWrite& write : batch_)
      if (write.file->waiting_.fetch_sub(1, std::memory_order_relaxed) == 1 &&
          write.file->closeWhenWritten_)
        ended.emplace_back(write.file, std::exchange(write.file->closeWhenWritten_, nullptr));
    done_.notifyAll();
  }
  // (What a file's end does, as a camera's last hold on its budget, may
  // malloc and free: once a file.)
  for (auto& [file, closed] : ended) closed(file->closeNow());
}

size_t DiskWriter::performRun(size_t first) {
  // The writes from `first` on that continue each other in one file.
  size_t count = 1;
  uint64_t end = batch_[first].offset + gst_buffer_get_size(batch_[first].bytes);
  while (first + count < batch_.size() && count < kMaxRun) {
    const DiskWrite& next = batch_[first + count];
    if (next.file != batch_[first].file || next.offset != end) break;
    end += gst_buffer_get_size(next.bytes);
    ++count;
  }
  File& file = *batch_[first].file;
  pieces_.clear();
  size_t mapped = 0;
  // After a file's first error its other writes are let go: a full disk
  // fails them all, and the muxer's error ends the file.
  if (file.error_ == 0 && file.fd_ >= 0) {
    for (; mapped < count; ++mapped) {
      if (!gst_buffer_map(batch_[first + mapped].bytes, &maps_[mapped], GST_MAP_READ)) break;
      pieces_.push_back({maps_[mapped].data, maps_[mapped].size});
    }
    writeAll(file, pieces_, batch_[first].offset);
  }
  for (size_t i = 0; i < mapped; ++i) gst_buffer_unmap(batch_[first + i].bytes, &maps_[i]);
  return count;
}

void DiskWriter::writeAll(File& file, std::vector<iovec>& pieces, uint64_t offset) {
  size_t next = 0;  // the first piece not wholly written
  while (next < pieces.size()) {
    ssize_t n = pwritev(file.fd_, pieces.data() + next, static_cast<int>(pieces.size() - next),
                        static_cast<off_t>(offset));
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) {
      file.error_ = n < 0 ? errno : ENOSPC;
      return;
    }
    offset += static_cast<uint64_t>(n);
    auto left = static_cast<size_t>(n);
    while (next < pieces.size() && left >= pieces[next].iov_len) left -= pieces[next++].iov_len;
    if (next < pieces.size()) {  // a piece written in part
      pieces[next].iov_base = static_cast<uint8_t*>(pieces[next].iov_base) + left;
      pieces[next].iov_len -= left;
    }
  }
}

}  // namespace wircam::recorder
