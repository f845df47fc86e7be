// GET /metrics as Prometheus reads it: the token (Bearer or Basic) needed,
// `promtool check metrics` content with the text, and Debian's prometheus
// scraping the recorder with a bearer token from a file: the frames' rate
// near the simulator's, and stream up falling to 0 when the device stops.
#include <gtest/gtest.h>

#include <fstream>

#include "http_fetch.h"
#include "prometheus_server.h"
#include "recorder_process.h"
#include "shell_command.h"
#include "simulated_device.h"
#include "wait_for.h"

namespace {

namespace fs = std::filesystem;
using namespace wircam::testing;
using std::chrono::milliseconds;

constexpr const char* kToken = "0123456789abcdef0123456789abcdef";

TEST(RecorderMetrics, TheTextIsPrometheussAndNeedsTheToken) {
  auto device = startSequenceDevice();
  RecorderProcess recorder(device->port(), {"--segment", "1", "--http", "127.0.0.1:0",
                                            "--http-token", kToken, "--duration", "30"});
  auto url = recorder.waitForLog("http://", milliseconds(10000));
  ASSERT_TRUE(url) << recorder.log();
  std::string stream = "stream=\"127.0.0.1-" + std::to_string(device->port()) + "-cam0\"";
  EXPECT_EQ(fetch(*url + "metrics").status, 401u);
  Headers bearer = {{"Authorization", std::string("Bearer ") + kToken}};
  // A segment closed: every family has its value.
  ASSERT_TRUE(waitFor(
      [&] {
        return fetch(*url + "metrics", "GET", bearer)
                   .body.find("wircam_segments_closed_total{" + stream + "} 1") !=
               std::string::npos;
      },
      milliseconds(10000)));
  auto metrics = fetch(*url + "metrics", "GET", bearer);
  EXPECT_EQ(metrics.status, 200u);
  EXPECT_EQ(metrics.contentType, "text/plain");
  for (const std::string& line : std::vector<std::string>{
           "wircam_build_info{version=\"", "wircam_stream_up{" + stream + "} 1",
           "wircam_camera_state{" + stream + ",state=\"live\"} 1", "wircam_battery_volts{" + stream,
           "# TYPE wircam_frames_received_total counter", "wircam_disk_free_bytes ",
           "wircam_http_connections "})
    EXPECT_NE(metrics.body.find(line), std::string::npos) << line << "\n" << metrics.body;
  // The link keeps the device's watchdog fed: PCD go out even without following.
  std::string pcd = "wircam_pcd_sent_total{" + stream + "} ";
  auto at = metrics.body.find(pcd);
  ASSERT_NE(at, std::string::npos) << metrics.body;
  EXPECT_GT(std::stoull(metrics.body.substr(at + pcd.size())), 5u);
  // Read when scraped, not once a second: each scrape, a few frames apart,
  // counts what the device has sent by then, give or take the frames on
  // their way (at most 6 under load; a once-a-second count lags by up to 15).
  std::string frames = "wircam_frames_received_total{" + stream + "} ";
  for (int i = 0; i < 6; ++i) {
    uint64_t sentBefore = device->stats().framesSentWhole;
    auto body = fetch(*url + "metrics", "GET", bearer).body;
    uint64_t sentAfter = device->stats().framesSentWhole;
    auto count = body.find(frames);
    ASSERT_NE(count, std::string::npos) << body;
    uint64_t scraped = std::stoull(body.substr(count + frames.size()));
    EXPECT_LE(scraped, sentAfter);
    EXPECT_GE(scraped + 6, sentBefore) << "scrape " << i;
    ASSERT_TRUE(waitFor([&] { return device->stats().framesSentWhole >= sentAfter + 4; }));
  }
  fs::path text = recorder.out().parent_path() / "metrics.txt";
  std::ofstream(text) << metrics.body;
  auto checked = runCommand("promtool check metrics < '" + text.string() + "'");
  EXPECT_EQ(checked.exitCode, 0) << checked.output;
  EXPECT_EQ(checked.output, "") << checked.output;  // no lint either
}

TEST(RecorderMetrics, PrometheusScrapesTheFrameRateAndSeesTheStreamGoDown) {
  if (!prometheusInstalled()) GTEST_SKIP() << "prometheus is not installed";
  auto device = startSequenceDevice();
  RecorderProcess recorder(device->port(),
                           {"--http", "127.0.0.1:0", "--http-token", kToken, "--duration", "60"});
  auto url = recorder.waitForLog("http://", milliseconds(10000));
  ASSERT_TRUE(url) << recorder.log();
  PrometheusServer prometheus(url->substr(7, url->size() - 8), kToken);  // "HOST:PORT"
  ASSERT_TRUE(prometheus.ready()) << prometheus.log();
  std::optional<double> rate;
  EXPECT_TRUE(waitFor(
      [&] {
        rate = prometheus.query("rate(wircam_frames_received_total[4s])");
        return rate && *rate > 12 && *rate < 18;
      },
      milliseconds(30000)))
      << "rate " << rate.value_or(-1) << "\n"
      << prometheus.log();
  EXPECT_EQ(prometheus.query("wircam_stream_up"), 1.0);
  device.reset();
  EXPECT_TRUE(
      waitFor([&] { return prometheus.query("wircam_stream_up") == 0.0; }, milliseconds(30000)))
      << recorder.log();
}

}  // namespace
