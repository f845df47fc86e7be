// Waits for a condition instead of sleeping a fixed time: returns as soon as
// `done()` holds, or false after `timeout` (stretched under a sanitizer).
#pragma once

#include <chrono>
#include <thread>

namespace wircam::testing {

// Under ThreadSanitizer everything runs several times slower (each memory
// access is checked), so the waits that only bound a failure stretch by this.
#if defined(__SANITIZE_THREAD__)
inline constexpr int kSanitizerSlowdown = 4;
#else
inline constexpr int kSanitizerSlowdown = 1;
#endif

// Under AddressSanitizer freed memory waits in a quarantine: resident
// memory is no measure of a leak there.
#if defined(__SANITIZE_ADDRESS__)
inline constexpr bool kAddressSanitizer = true;
#else
inline constexpr bool kAddressSanitizer = false;
#endif

// `timeout`, stretched under a sanitizer.
inline std::chrono::milliseconds patience(std::chrono::milliseconds timeout) {
  return timeout * kSanitizerSlowdown;
}

template <typename Condition>
bool waitFor(Condition done, std::chrono::milliseconds timeout = std::chrono::seconds(5)) {
  auto end = std::chrono::steady_clock::now() + patience(timeout);
  while (!done()) {
    if (std::chrono::steady_clock::now() >= end) return false;
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
  }
  return true;
}

}  // namespace wircam::testing
