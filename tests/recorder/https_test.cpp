// wirc-recorder --http-cert/--http-key: HTTPS with certificates made by
// openssl for the test (a CA and a server certificate for 127.0.0.1), read
// by curl trusting that CA: the API over TLS with the token, a client that
// does not trust the CA refused by its own check, a client that speaks
// plain HTTP to the port closed without harm to the next one.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>

#include "recorder_process.h"
#include "shell_command.h"
#include "simulated_device.h"
#include "test_certificates.h"

namespace {

namespace fs = std::filesystem;
using namespace wircam::testing;
using std::chrono::milliseconds;

constexpr const char* kToken = "0123456789abcdef0123456789abcdef";

// curl's exit code and what it printed: the body, then the HTTP status.
CommandRun curl(const std::string& options, const std::string& url) {
  return runCommand("curl -sS --max-time 10 -w '\\n%{http_code}' " + options + " '" + url + "'");
}

TEST(WircRecorderHttps, TheApiIsServedOverTlsToClientsThatTrustTheCertificate) {
  fs::path certificates = fs::temp_directory_path() / ("wirc-https-" + std::to_string(getpid()));
  ASSERT_TRUE(makeCertificates(certificates));
  auto device = startSequenceDevice();
  RecorderProcess recorder(device->port(),
                           {"--http", "127.0.0.1:0", "--http-token", kToken, "--http-cert",
                            (certificates / "server.pem").string(), "--http-key",
                            (certificates / "server.key").string(), "--duration", "30"});
  auto url = recorder.waitForLog("https://", milliseconds(10000));
  ASSERT_TRUE(url) << recorder.log();
  std::string bearer = std::string("-H 'Authorization: Bearer ") + kToken + "'";
  std::string trusted = "--cacert '" + (certificates / "ca.pem").string() + "' ";

  auto cameras = curl(trusted + bearer, *url + "api/cameras");
  ASSERT_EQ(cameras.exitCode, 0) << cameras.output;
  EXPECT_TRUE(cameras.output.ends_with("\n200")) << cameras.output;
  auto list =
      nlohmann::json::parse(cameras.output.substr(0, cameras.output.rfind('\n')), nullptr, false);
  EXPECT_TRUE(list.is_array()) << cameras.output;
  EXPECT_TRUE(curl(trusted, *url + "api/cameras").output.ends_with("\n401"));

  // Not trusting the test CA: curl's own check refuses (exit 60).
  EXPECT_EQ(curl(bearer, *url + "api/cameras").exitCode, 60);
  // Plain HTTP to the HTTPS port: no answer, the connection closed...
  std::string plain = "http://" + url->substr(8);
  auto refused = curl(bearer, plain + "api/cameras");
  EXPECT_NE(refused.exitCode, 0) << refused.output;
  // ...and the server serves the next client as before.
  EXPECT_TRUE(curl(trusted + bearer, *url + "api/status").output.ends_with("\n200"));
  fs::remove_all(certificates);
}

TEST(WircRecorderHttps, ACertificateThatCannotBeReadIsSaidAtStart) {
  RecorderProcess recorder(
      0, {"--device", "127.0.0.1:9", "--out", "/tmp/unused", "--http", "127.0.0.1:0", "--http-cert",
          "/nonexistent/server.pem", "--http-key", "/nonexistent/server.key"});
  EXPECT_NE(recorder.wait(), 0);
  EXPECT_NE(recorder.log().find("--http-cert /nonexistent/server.pem"), std::string::npos)
      << recorder.log();
  RecorderProcess alone(0, {"--device", "127.0.0.1:9", "--out", "/tmp/unused", "--http",
                            "127.0.0.1:0", "--http-cert", "/x.pem"});
  EXPECT_EQ(alone.wait(), 2);
  EXPECT_NE(alone.log().find("--http-cert and --http-key go together"), std::string::npos)
      << alone.log();
}

TEST(WircRecorderHttps, ATokenInClearOnTheNetworkIsWarnedOfOnce) {
  RecorderProcess recorder(0, {"--device", "127.0.0.1:9", "--out", "/tmp/unused", "--http",
                               "0.0.0.0:0", "--http-token", kToken, "--duration", "1"});
  recorder.wait();
  auto log = recorder.log();
  auto warning = std::string("the access token travels in clear over plain HTTP on 0.0.0.0");
  auto at = log.find(warning);
  EXPECT_NE(at, std::string::npos) << log;
  EXPECT_EQ(log.find(warning, at + 1), std::string::npos) << log;
}

}  // namespace
