// A mutex and its scoped lock that clang's -Wthread-safety understands, so
// that "guarded by" is checked by the compiler rather than said in a
// comment: fields marked WIRCAM_GUARDED_BY(mutex_) may only be touched with
// mutex_ held. (libstdc++'s std::mutex carries no such annotations.) Under
// GCC the annotations are empty and these are std::mutex and a lock guard.
#pragma once

#include <mutex>

#if defined(__clang__)
#define WIRCAM_THREAD_ANNOTATION(x) __attribute__((x))
#else
#define WIRCAM_THREAD_ANNOTATION(x)
#endif

#define WIRCAM_CAPABILITY(name) WIRCAM_THREAD_ANNOTATION(capability(name))
#define WIRCAM_SCOPED_CAPABILITY WIRCAM_THREAD_ANNOTATION(scoped_lockable)
#define WIRCAM_GUARDED_BY(mutex) WIRCAM_THREAD_ANNOTATION(guarded_by(mutex))
#define WIRCAM_REQUIRES(...) WIRCAM_THREAD_ANNOTATION(requires_capability(__VA_ARGS__))
#define WIRCAM_ACQUIRE(...) WIRCAM_THREAD_ANNOTATION(acquire_capability(__VA_ARGS__))
#define WIRCAM_RELEASE(...) WIRCAM_THREAD_ANNOTATION(release_capability(__VA_ARGS__))
#define WIRCAM_EXCLUDES(...) WIRCAM_THREAD_ANNOTATION(locks_excluded(__VA_ARGS__))
// For a wrapper whose body the analysis cannot follow: a condition's wait
// calls its caller's predicate, which needs the caller's mutex under the
// caller's name for it.
#define WIRCAM_NO_THREAD_SAFETY_ANALYSIS WIRCAM_THREAD_ANNOTATION(no_thread_safety_analysis)

namespace wircam {

class WIRCAM_CAPABILITY("mutex") Mutex {
 public:
  void lock() WIRCAM_ACQUIRE() { mutex_.lock(); }
  void unlock() WIRCAM_RELEASE() { mutex_.unlock(); }

 private:
  std::mutex mutex_;
};

// Holds any of the mutexes above (Mutex, PriorityInheritingMutex) for its
// scope, as the analysis sees it; std::lock_guard carries no annotations.
template <class Lockable = Mutex>
class WIRCAM_SCOPED_CAPABILITY MutexLock {
 public:
  explicit MutexLock(Lockable& mutex) WIRCAM_ACQUIRE(mutex) : mutex_(mutex) { mutex_.lock(); }
  ~MutexLock() WIRCAM_RELEASE() {
    if (held_) mutex_.unlock();
  }
  MutexLock(const MutexLock&) = delete;
  MutexLock& operator=(const MutexLock&) = delete;

  // Lets go for a while (work done outside the lock), then takes it again.
  void unlock() WIRCAM_RELEASE() {
    mutex_.unlock();
    held_ = false;
  }
  void lock() WIRCAM_ACQUIRE() {
    mutex_.lock();
    held_ = true;
  }

 private:
  Lockable& mutex_;
  bool held_ = true;
};

}  // namespace wircam
