// wirc-recorder recording a device that floods its control connection with
// garbage (memory and log stay small, and SIGINT still ends it), or that
// refuses the login (said at once, with the reason in the status).
#include <gtest/gtest.h>
#include <signal.h>

#include <nlohmann/json.hpp>

#include "http_fetch.h"
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

TEST(WircRecorderHostileDevice, ARefusedLoginIsLoggedAtOnceAndItsReasonIsInTheStatus) {
  ScriptedPeer peer({.chunks = {bytesOf(wircam::wirc::Err{
                         static_cast<uint8_t>(wircam::wirc::Command::Tl),
                         static_cast<uint16_t>(wircam::wirc::ErrorCode::Unauthorised)})}});
  RecorderProcess recorder(peer.port(), {"--http", "127.0.0.1:0", "--duration", "60"});
  auto url = recorder.waitForLog("http://", milliseconds(10000));
  ASSERT_TRUE(url) << recorder.log();
  auto start = std::chrono::steady_clock::now();
  std::string reason;
  ASSERT_TRUE(waitFor(
      [&] {
        auto status = nlohmann::json::parse(fetch(*url + "api/status").body, nullptr, false);
        if (status.is_discarded()) return false;
        reason = status["streams"][0].value("link_reason", "");
        return reason.find("unauthorised") != std::string::npos;
      },
      milliseconds(2000)))
      << reason << recorder.log();
  EXPECT_LT(std::chrono::steady_clock::now() - start, patience(milliseconds(1000)));
  EXPECT_NE(recorder.log().find("refused the login: unauthorised"), std::string::npos)
      << recorder.log();
}

}  // namespace
