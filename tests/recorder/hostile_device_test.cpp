// wirc-recorder recording a device that floods its control connection with
// garbage: memory and log stay small, and SIGINT still ends it.
#include <gtest/gtest.h>
#include <signal.h>

#include "misbehaving_peers.h"
#include "process_memory.h"
#include "recorder_process.h"
#include "wait_for.h"

namespace {

using namespace wircam::testing;
using std::chrono::milliseconds;

TEST(WircRecorderHostileDevice, GarbageOnTheControlConnectionCostsACounterNotMemory) {
  ScriptedPeer peer;
  std::vector<uint8_t> garbage;
  for (int i = 0; i < 4096; ++i) garbage.insert(garbage.end(), {0xAA, 0xBB});
  peer.play({.chunks = {peer.wst()}, .flood = garbage});
  RecorderProcess recorder(peer.port(), {"--duration", "60"});
  ASSERT_TRUE(waitFor([&] { return peer.connections() >= 2; }, milliseconds(10000)))
      << recorder.log();
  long early = residentKb(recorder.pid());
  // Keep flooding for a few more reconnects.
  ASSERT_TRUE(waitFor([&] { return peer.connections() >= 4; }, milliseconds(15000)));
  EXPECT_LT(residentKb(recorder.pid()) - early, 20 * 1024);
  EXPECT_LT(recorder.log().size(), 64u * 1024) << "the log grows with the garbage";
  EXPECT_NE(recorder.log().find("dropped as misbehaving"), std::string::npos) << recorder.log();
  recorder.signal(SIGINT);
  auto start = std::chrono::steady_clock::now();
  recorder.wait();
  // Nothing was recorded, so nothing holds the stop back.
  EXPECT_LT(std::chrono::steady_clock::now() - start, milliseconds(5000));
}

}  // namespace
