// wirc-recorder --marvelmind: the simulated dashboard reports the car's true
// position while the recorder follows the tag, and the positions reach the
// recording, /api/status and the live view's map.
#include <gtest/gtest.h>

#include <fstream>
#include <nlohmann/json.hpp>
#include <thread>

#include "devices/wirc/device.h"
#include "follow_scene.h"
#include "headless_chromium.h"
#include "http_fetch.h"
#include "marvelmind_dashboard.h"
#include "recorder_process.h"
#include "wait_for.h"

namespace {

namespace fs = std::filesystem;
using namespace wircam;
using namespace wircam::testing;
using namespace std::chrono_literals;

constexpr double kNoise = 0.01;       // m, per axis
constexpr double kPollSeconds = 0.1;  // the recorder polls at 10 Hz

// A followed car whose position a simulated dashboard reports (beacon 5).
struct PositionedCar {
  std::shared_ptr<sim::FollowScene> scene;
  std::unique_ptr<wirc::Device> device;
  std::unique_ptr<sim::MarvelmindDashboard> dashboard;
  fs::path truth;

  explicit PositionedCar(const fs::path& folder) : truth(folder / "truth.jsonl") {
    auto created = sim::FollowScene::create({});
    if (!created) return;
    scene = std::move(*created);
    scene->writeTruthTo(truth.string());
    auto started = wirc::Device::start({.port = 0, .fragmentSize = 8000}, scene);
    if (started) device = std::move(*started);
    auto running = sim::MarvelmindDashboard::start(
        {.beacons = {5}, .rate = 16, .noise = kNoise}, [s = scene.get()](size_t) {
          auto now = s->truthNow();
          return std::array<double, 3>{now.car.x, now.car.y, 0.25};
        });
    if (running) dashboard = std::move(*running);
  }
  std::vector<std::string> arguments() const {
    return {"--detect",
            "tag36h11",
            "--follow",
            "--marvelmind",
            "127.0.0.1:" + std::to_string(dashboard->port()),
            "--beacon",
            "5"};
  }
};

struct TruthSample {
  int64_t unixMs;
  double x, y;
};

std::vector<TruthSample> readTruth(const fs::path& file) {
  std::vector<TruthSample> samples;
  std::ifstream in(file);
  for (std::string text; std::getline(in, text);) {
    auto line = nlohmann::json::parse(text, nullptr, false);
    if (line.is_discarded()) continue;  // the line being written at the end
    samples.push_back({line["unix_ms"], line["car"]["x"], line["car"]["y"]});
  }
  return samples;
}

// "2026-11-22T09:58:35.945Z" → ms since 1970.
int64_t unixMsOf(const std::string& utc) {
  std::tm tm{};
  int ms = 0;
  sscanf(utc.c_str(), "%d-%d-%dT%d:%d:%d.%dZ", &tm.tm_year, &tm.tm_mon, &tm.tm_mday, &tm.tm_hour,
         &tm.tm_min, &tm.tm_sec, &ms);
  tm.tm_year -= 1900;
  tm.tm_mon -= 1;
  return static_cast<int64_t>(timegm(&tm)) * 1000 + ms;
}

TEST(RecorderPositions, ReachTheRecordingWithinNoiseOfTheTruthAndAtMostAPollLate) {
  auto folder = fs::temp_directory_path() / ("wirc-positions-" + std::to_string(getpid()));
  fs::remove_all(folder);
  fs::create_directories(folder);
  PositionedCar car(folder);
  ASSERT_TRUE(car.device && car.dashboard);
  auto args = car.arguments();
  args.insert(args.end(), {"--duration", "6"});
  RecorderProcess recorder(car.device->port(), args);
  ASSERT_EQ(recorder.wait(), 0) << recorder.log();
  car.device.reset();  // the truth file is complete

  auto truth = readTruth(car.truth);
  ASSERT_GT(truth.size(), 50u);
  // The car drove (the test means something only if it moved).
  double travelled = std::hypot(truth.back().x - truth.front().x, truth.back().y - truth.front().y);
  EXPECT_GT(travelled, 0.5);

  int positions = 0, matched = 0, unwitnessed = 0;
  double worst = 0;
  for (const auto& sidecar : recorder.files(".jsonl")) {
    std::ifstream in(sidecar);
    for (std::string text; std::getline(in, text);) {
      auto line = nlohmann::json::parse(text);
      if (line["type"] != "position") continue;
      EXPECT_EQ(line["beacon"], 5);
      ASSERT_TRUE(line.contains("pts") && line.contains("utc") && line.contains("z"));
      int64_t at = unixMsOf(line["utc"]);
      // Measured after the stream stopped (the last moments of the stop):
      // the scene moves the car on with the wall clock, but writes a truth
      // line only with a frame, so nothing here says where the car was.
      if (at > truth.back().unixMs + 70) continue;
      // The truth somewhere between one poll period (and a frame of the
      // scene's stepping) before the line's time and a frame after it.
      double best = 1e9;
      bool witnessed = false;
      for (const auto& sample : truth)
        if (sample.unixMs >= at - (kPollSeconds * 1000 + 70) && sample.unixMs <= at + 70) {
          witnessed = true;
          best = std::min(best, std::hypot(sample.x - line["x"].get<double>(),
                                           sample.y - line["y"].get<double>()));
        }
      // A busy machine can hold the scene's frames back for longer than
      // that window (seen beside the whole suite); with no truth line in
      // it, nothing says where the car was.
      if (!witnessed) {
        ++unwitnessed;
        continue;
      }
      ++positions;
      worst = std::max(worst, best);
      // 5 sigma of the 2-D noise, plus the centimetre rounding.
      if (best <= 5 * kNoise * std::sqrt(2.0) + 0.01)
        ++matched;
      else
        ADD_FAILURE() << text << ": " << best << " m from the truth; truth from "
                      << truth.front().unixMs << " to " << truth.back().unixMs;
    }
  }
  // 10 polls a second for most of the 6 s recorded.
  EXPECT_GT(positions, 40) << unwitnessed << " without a truth line near them";
  EXPECT_EQ(matched, positions) << "the worst was " << worst << " m from the truth";
  fs::remove_all(folder);
}

TEST(RecorderPositions, StatusCarriesTheLatestAndTheMapDrawsTheTrail) {
  auto folder = fs::temp_directory_path() / ("wirc-positions-map-" + std::to_string(getpid()));
  fs::remove_all(folder);
  fs::create_directories(folder);
  PositionedCar car(folder);
  ASSERT_TRUE(car.device && car.dashboard);
  auto args = car.arguments();
  args.insert(args.end(), {"--http", "127.0.0.1:0", "--duration", "60"});
  RecorderProcess recorder(car.device->port(), args);
  auto url = recorder.waitForLog("http://", 10s);
  ASSERT_TRUE(url) << recorder.log();
  // Until the first position has come through.
  nlohmann::json status;
  ASSERT_TRUE(waitFor(
      [&] {
        status = nlohmann::json::parse(fetch(*url + "api/status").body, nullptr, false);
        return status.is_object() && status["streams"][0]["position"].is_object();
      },
      10s))
      << recorder.log();
  auto position = status["streams"][0]["position"];
  ASSERT_TRUE(position.is_object()) << status.dump();
  EXPECT_EQ(position["beacon"], 5);
  EXPECT_EQ(position["stale"], false);
  auto truthNow = car.scene->truthNow().car;
  EXPECT_NEAR(position["x"].get<double>(), truthNow.x, 0.3);

  if (chromiumInstalled()) {
    // Kept beside the build for people to look at.
    auto shot = fs::path(WIRCAM_SCREENSHOT_DIR) / "live-view-positions.png";
    ASSERT_TRUE(screenshot(*url, shot, 800, 1000));
    auto picture = readPng(shot);
    // The first vehicle's trail and dot are drawn in #4fc3f7.
    EXPECT_GT(picture.count(0x4f, 0xc3, 0xf7, 12), 40) << "no trail on the map in " << shot;
  }

  // The dashboard stops: the position goes stale in the status.
  car.dashboard.reset();
  nlohmann::json stale;
  waitFor(
      [&] {
        auto p = nlohmann::json::parse(fetch(*url + "api/status").body)["streams"][0]["position"];
        if (p.is_object() && p.value("stale", false)) stale = p;
        return stale.is_object();
      },
      10s);
  ASSERT_TRUE(stale.is_object()) << recorder.log();
  EXPECT_NE(stale["stale_reason"].get<std::string>().find("no reply"), std::string::npos);
  recorder.signal(SIGTERM);
  EXPECT_EQ(recorder.wait(), 0);
  bool staleLine = false;
  for (const auto& sidecar : recorder.files(".jsonl")) {
    std::ifstream in(sidecar);
    for (std::string text; std::getline(in, text);)
      staleLine |= nlohmann::json::parse(text)["type"] == "position-stale";
  }
  EXPECT_TRUE(staleLine) << "no position-stale line in the telemetry";
  fs::remove_all(folder);
}

}  // namespace
