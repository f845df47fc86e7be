#include "camera/disk_budget.h"

#include <utility>

namespace wircam::recorder {

namespace {

// Written bytes waiting to be freed past this many are freed at once (a
// camera that stopped handing over cannot hold them all).
constexpr size_t kMaxGivenBack = 256;
// A frame is a few of the muxer's buffers: the lists rarely grow past
// this, so the writer rarely grows them (a malloc).
constexpr size_t kReserved = 32;

}  // namespace

DiskBudget::DiskBudget(uint64_t bound) : bound_(bound) {
  MutexLock lock(laneMutex_);
  writes_.reserve(kReserved);
  givenBack_.reserve(kReserved);
  freeing_.reserve(kReserved);
}

DiskBudget::~DiskBudget() {
  MutexLock lock(laneMutex_);
  for (GstBuffer* bytes : givenBack_) gst_buffer_unref(bytes);
  // (None wait: a lane with writes keeps itself alive until they are taken.)
  for (DiskWrite& write : writes_) gst_buffer_unref(write.bytes);
}

bool DiskBudget::queue(DiskWrite&& write, const std::shared_ptr<DiskBudget>& self) {
  waiting_.fetch_add(gst_buffer_get_size(write.bytes), std::memory_order_relaxed);
  std::unique_lock freeing(freeingMutex_, std::try_to_lock);
  bool toList;
  {
    MutexLock lock(laneMutex_);
    writes_.push_back(std::move(write));
    if (freeing) freeing_.swap(givenBack_);  // (freeing_ is empty: both keep a capacity)
    toList = !listed_;
    if (toList) listed_ = self;
  }
  if (freeing) {
    for (GstBuffer* bytes : freeing_) gst_buffer_unref(bytes);
    freeing_.clear();
  }
  return toList;
}

std::shared_ptr<DiskBudget> DiskBudget::take(std::vector<DiskWrite>& into) {
  MutexLock lock(laneMutex_);
  into.swap(writes_);  // (both keep a capacity: no malloc)
  return std::move(listed_);
}

void DiskBudget::giveBack(const std::vector<DiskWrite>& written) {
  uint64_t bytes = 0;
  MutexLock lock(laneMutex_);
  for (const DiskWrite& write : written) {
    bytes += gst_buffer_get_size(write.bytes);
    if (givenBack_.size() < kMaxGivenBack)
      givenBack_.push_back(write.bytes);
    else
      gst_buffer_unref(write.bytes);  // (never in a camera that keeps handing over)
  }
  waiting_.fetch_sub(bytes, std::memory_order_relaxed);
}

}  // namespace wircam::recorder
