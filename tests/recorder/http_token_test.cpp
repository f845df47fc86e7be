// wirc-recorder --http-token: every request needs the token, as a Bearer
// header or the cookie /login sets; without a token the server stays on
// this machine.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include "http_fetch.h"
#include "recorder_process.h"
#include "simulated_device.h"

namespace {

using namespace wircam::testing;
using std::chrono::milliseconds;

constexpr const char* kToken = "0123456789abcdef0123456789abcdef";

TEST(WircRecorderHttpToken, EveryRequestNeedsTheTokenAsBearerOrCookie) {
  auto device = startSequenceDevice();
  ASSERT_TRUE(device);
  RecorderProcess recorder(device->port(),
                           {"--http", "127.0.0.1:0", "--http-token", kToken, "--duration", "30"});
  auto url = recorder.waitForLog("http://", milliseconds(10000));
  ASSERT_TRUE(url) << recorder.log();
  std::string camera = "127.0.0.1-" + std::to_string(device->port()) + "-cam0";
  for (const std::string& path : std::vector<std::string>{
           "api/status", "api/cameras", "api/recordings", "recordings", "live/" + camera + ".mjpg",
           "api/cameras/" + camera + "/snapshot.jpg", "api/events"}) {
    auto refused = fetch(*url + path);
    EXPECT_EQ(refused.status, 401u) << path;
    EXPECT_EQ(refused.contentType, "application/json") << path;
    EXPECT_EQ(refused.authenticate, "Bearer realm=\"wirc-recorder\"") << path;
    auto wrong = fetch(*url + path, "GET", {{"Authorization", "Bearer 0123456789abcdef"}});
    EXPECT_EQ(wrong.status, 401u) << path;
  }
  // The page shows the sign-in form instead, and /login is open.
  auto page = fetch(*url);
  EXPECT_EQ(page.status, 401u);
  EXPECT_NE(page.body.find("Access token"), std::string::npos);
  EXPECT_EQ(fetch(*url + "login").status, 200u);
  // With the token: the header, or the cookie among others.
  auto bearer =
      fetch(*url + "api/status", "GET", {{"Authorization", std::string("Bearer ") + kToken}});
  EXPECT_EQ(bearer.status, 200u);
  EXPECT_TRUE(nlohmann::json::parse(bearer.body).contains("streams"));
  auto cookie = fetch(*url + "api/cameras", "GET",
                      {{"Cookie", std::string("theme=dark; wircam_token=") + kToken + "; x=1"}});
  EXPECT_EQ(cookie.status, 200u);
  EXPECT_EQ(fetch(*url, "GET", {{"Cookie", std::string("wircam_token=") + kToken}}).status, 200u);
}

TEST(WircRecorderHttpToken, WithoutATokenTheServerStaysOnThisMachine) {
  RecorderProcess open(0,
                       {"--device", "127.0.0.1:9", "--out", "/tmp/unused", "--http", "0.0.0.0:0"});
  EXPECT_EQ(open.wait(), 2);
  EXPECT_NE(open.log().find("without authentication: give --http-token T"), std::string::npos)
      << open.log();
  RecorderProcess shortToken(0, {"--device", "127.0.0.1:9", "--out", "/tmp/unused", "--http", ":0",
                                 "--http-token", "short"});
  EXPECT_EQ(shortToken.wait(), 2);
}

}  // namespace
