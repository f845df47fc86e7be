// Waits for a condition instead of sleeping a fixed time: returns as soon as
// `done()` holds, or false after `timeout` (stretched under a sanitizer).
#pragma once

#include <algorithm>
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

// Looks again after 1 ms, then ever less often, up to every 20 ms: many
// conditions ask a server (the recorder's API, Prometheus, a page), and
// asked every 2 ms for seconds, those servers took a good share of the two
// cores the suites share. A wait is late by at most 20 ms for it.
template <typename Condition>
bool waitFor(Condition done, std::chrono::milliseconds timeout = std::chrono::seconds(5)) {
  auto end = std::chrono::steady_clock::now() + patience(timeout);
  auto pause = std::chrono::milliseconds(1);
  while (!done()) {
    if (std::chrono::steady_clock::now() >= end) return false;
    std::this_thread::sleep_for(pause);
    pause = std::min(pause * 2, std::chrono::milliseconds(20));
  }
  return true;
}

}  // namespace wircam::testing
