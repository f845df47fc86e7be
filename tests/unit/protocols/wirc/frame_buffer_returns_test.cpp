#include "wirc/frame_buffer_returns.h"

#include <gtest/gtest.h>

#include <set>
#include <thread>

namespace {

using wircam::wirc::FrameBuffer;
using wircam::wirc::FrameBufferReturns;

TEST(FrameBufferReturns, HandsBackTheSameMemoryAndKeepsNoMoreThanTwo) {
  FrameBufferReturns returns;
  EXPECT_FALSE(returns.take());
  std::set<const uint8_t*> given;
  for (int i = 0; i < 4; ++i) {
    FrameBuffer buffer(16000);
    given.insert(buffer.data());
    returns.put(std::move(buffer));
  }
  auto first = returns.take(), second = returns.take();
  ASSERT_TRUE(first && second);
  EXPECT_TRUE(given.count(first->data()) && given.count(second->data()));
  EXPECT_EQ(first->capacity(), 16000u);
  EXPECT_FALSE(returns.take());  // the other two were freed
}

TEST(FrameBufferReturns, TakesBuffersPutFromAnotherThread) {
  FrameBufferReturns returns;
  std::thread downstream([&] {
    for (int i = 0; i < 1000; ++i) returns.put(FrameBuffer(64));
  });
  int taken = 0;
  for (int i = 0; i < 100000 && taken < 10; ++i)
    if (returns.take()) ++taken;
  downstream.join();
  int left = 0;
  while (returns.take()) ++left;
  EXPECT_GE(taken + left, 1);
  EXPECT_LE(left, static_cast<int>(FrameBufferReturns::kMaxWaiting));  // the rest were freed
}

}  // namespace
