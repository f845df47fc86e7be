// Waits for a condition instead of sleeping a fixed time: returns as soon as
// `done()` holds, or false after `timeout`.
#pragma once

#include <chrono>
#include <thread>

namespace wircam::testing {

template <typename Condition>
bool waitFor(Condition done, std::chrono::milliseconds timeout = std::chrono::seconds(5)) {
  auto end = std::chrono::steady_clock::now() + timeout;
  while (!done()) {
    if (std::chrono::steady_clock::now() >= end) return false;
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
  }
  return true;
}

}  // namespace wircam::testing
