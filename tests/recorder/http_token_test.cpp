// wirc-recorder --http-token: every request needs the token, as a Bearer
// header or the cookie /login sets; without a token the server stays on
// this machine.
#include <gtest/gtest.h>

#include <filesystem>
#include <nlohmann/json.hpp>
#include <thread>

#include "http_fetch.h"
#include "recorder_process.h"
#include "shell_command.h"
#include "simulated_device.h"
#include "wait_for.h"

namespace {

using namespace wircam::testing;
using std::chrono::milliseconds;

constexpr const char* kToken = "0123456789abcdef0123456789abcdef";

// A recorder of the sequence device with the web server and the token.
struct TokenRecorder {
  std::unique_ptr<wircam::wirc::Device> device = startSequenceDevice();
  RecorderProcess recorder{device->port(),
                           {"--http", "127.0.0.1:0", "--http-token", kToken, "--duration", "30"}};
  std::optional<std::string> url = recorder.waitForLog("http://", milliseconds(10000));
  std::string camera = "127.0.0.1-" + std::to_string(device->port()) + "-cam0";
};

TEST(WircRecorderHttpToken, EveryRequestNeedsTheTokenAsBearerOrCookie) {
  TokenRecorder served;
  auto& url = served.url;
  const auto& camera = served.camera;
  ASSERT_TRUE(url) << served.recorder.log();
  for (const std::string& path : std::vector<std::string>{
           "api/status", "api/cameras", "api/recordings", "recordings", "live/" + camera + ".mjpg",
           "api/cameras/" + camera + "/snapshot.jpg", "api/events"}) {
    auto refused = fetch(*url + path);
    EXPECT_EQ(refused.status, 401u) << path;
    EXPECT_EQ(refused.contentType, "application/json") << path;
    EXPECT_EQ(refused.authenticate, "Basic realm=\"wirc-recorder\", Bearer realm=\"wirc-recorder\"")
        << path;
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

// What VLC, OpenCV and Home Assistant send for http://user:TOKEN@host/...:
// Basic credentials, any user name, the token as the password.
TEST(WircRecorderHttpToken, ClientsWithCredentialsInTheUrlGetTheLiveStream) {
  TokenRecorder served;
  auto& url = served.url;
  const auto& camera = served.camera;
  ASSERT_TRUE(url) << served.recorder.log();
  auto withCredentials = [&](const std::string& password) {
    std::string live =
        "http://viewer:" + password + "@" + url->substr(7) + "live/" + camera + ".mjpg";
    return runCommand("timeout 20 gst-launch-1.0 -q souphttpsrc location='" + live +
                      "' ! multipartdemux ! jpegdec ! fakesink num-buffers=5");
  };
  auto played = withCredentials(kToken);
  EXPECT_EQ(played.exitCode, 0) << played.output;
  auto refused = withCredentials("0123456789abcdef0123456789abcdeX");
  EXPECT_NE(refused.exitCode, 0) << refused.output;
  EXPECT_NE(refused.output.find("Unauthorized"), std::string::npos) << refused.output;
  // Python's OpenCV (Debian's python3-opencv) opens the URL as it is, and
  // not with a wrong password.
  auto opencv = [&](const std::string& password) {
    std::string live =
        "http://viewer:" + password + "@" + url->substr(7) + "live/" + camera + ".mjpg";
    return runCommand(
               "/usr/bin/python3 -c \"import cv2, sys; ok, frame = "
               "cv2.VideoCapture(sys.argv[1]).read(); print(ok, frame.shape if ok else None)\" '" +
               live + "' 2>/dev/null")
        .output;
  };
  // (OpenCV prints its backend's warnings before the answer.)
  EXPECT_TRUE(opencv(kToken).ends_with("True (288, 352, 3)\n")) << opencv(kToken);
  auto wrongPassword = opencv("0123456789abcdef0123456789abcdeX");
  EXPECT_TRUE(wrongPassword.ends_with("False None\n")) << wrongPassword;
  // A script's Basic header works on the API too.
  std::string pair = std::string("script:") + kToken;
  gchar* basic = g_base64_encode(reinterpret_cast<const guchar*>(pair.data()), pair.size());
  EXPECT_EQ(
      fetch(*url + "api/cameras", "GET", {{"Authorization", std::string("Basic ") + basic}}).status,
      200u);
  g_free(basic);
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

TEST(WircRecorderHttpToken, DeletingARecordingNeedsTheTokenAndAFinishedSegment) {
  auto device = startSequenceDevice();
  ASSERT_TRUE(device);
  RecorderProcess recorder(device->port(), {"--http", "127.0.0.1:0", "--http-token", kToken,
                                            "--segment", "1", "--duration", "30"});
  auto url = recorder.waitForLog("http://", milliseconds(10000));
  ASSERT_TRUE(url) << recorder.log();
  Headers token = {{"Authorization", std::string("Bearer ") + kToken}};
  nlohmann::json segments;
  waitFor(
      [&] {
        segments = nlohmann::json::parse(fetch(*url + "api/recordings", "GET", token).body, nullptr,
                                         false);
        return segments.is_array() && !segments.empty();
      },
      milliseconds(10000));
  ASSERT_FALSE(segments.empty());
  std::string file = segments[0]["file"];
  auto path = recorder.out() / file;
  ASSERT_TRUE(std::filesystem::exists(path));
  EXPECT_EQ(fetch(*url + "api/recordings/" + file, "DELETE").status, 401u);
  EXPECT_TRUE(std::filesystem::exists(path));
  auto deleted = fetch(*url + "api/recordings/" + file, "DELETE", token);
  EXPECT_EQ(deleted.status, 200u) << deleted.body;
  EXPECT_FALSE(std::filesystem::exists(path));
  EXPECT_FALSE(std::filesystem::exists(std::filesystem::path(path).replace_extension(".jsonl")));
  auto after = nlohmann::json::parse(fetch(*url + "api/recordings", "GET", token).body);
  for (const auto& entry : after) EXPECT_NE(entry["file"], file);
  // Not twice, not outside the folder, not the segment being written.
  EXPECT_EQ(fetch(*url + "api/recordings/" + file, "DELETE", token).status, 404u);
  // (libsoup itself refuses a path that climbs out with 400; either way, refused.)
  auto climbing = fetch(*url + "api/recordings/..%2F..%2Fetc%2Fpasswd", "DELETE", token).status;
  EXPECT_TRUE(climbing == 400u || climbing == 404u) << climbing;
  EXPECT_TRUE(std::filesystem::exists("/etc/passwd"));
  auto status = nlohmann::json::parse(fetch(*url + "api/status", "GET", token).body);
  std::string open = status["streams"][0]["segment"];
  auto busy = fetch(*url + "api/recordings/" + open, "DELETE", token);
  EXPECT_EQ(busy.status, 409u) << busy.body;
  EXPECT_TRUE(std::filesystem::exists(recorder.out() / open));
}

TEST(WircRecorderHttpToken, WithoutATokenNothingCanBeDeleted) {
  auto device = startSequenceDevice();
  ASSERT_TRUE(device);
  RecorderProcess recorder(device->port(), {"--http", "127.0.0.1:0", "--duration", "30"});
  auto url = recorder.waitForLog("http://", milliseconds(10000));
  ASSERT_TRUE(url) << recorder.log();
  auto refused = fetch(*url + "api/recordings/anything.mkv", "DELETE");
  EXPECT_EQ(refused.status, 403u);
  EXPECT_NE(refused.body.find("--http-token"), std::string::npos) << refused.body;
}

}  // namespace
