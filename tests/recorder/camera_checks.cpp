#include "camera_checks.h"

#include <gtest/gtest.h>
#include <signal.h>

#include <chrono>
#include <fstream>

#include "http_fetch.h"
#include "wait_for.h"

namespace wircam::testing {

std::string cameraName(uint16_t port) { return "127.0.0.1-" + std::to_string(port) + "-cam0"; }

uint64_t indexedFrames(const std::filesystem::path& out, const std::string& camera) {
  std::ifstream in(out / "index.json");
  auto index = nlohmann::json::parse(in, nullptr, false);
  uint64_t frames = 0;
  if (index.is_object())
    for (const auto& segment : index["segments"])
      if (segment["camera"] == camera) frames += segment["frames"].get<uint64_t>();
  return frames;
}

namespace {
nlohmann::json entryNamed(const nlohmann::json& list, const std::string& name) {
  if (list.is_array())
    for (const auto& entry : list)
      if (entry["name"] == name) return entry;
  return nullptr;
}
}  // namespace

nlohmann::json cameraEntry(const std::string& url, const std::string& camera,
                           const Headers& headers) {
  return entryNamed(
      nlohmann::json::parse(fetch(url + "api/cameras", "GET", headers).body, nullptr, false),
      camera);
}

nlohmann::json streamEntry(const std::string& url, const std::string& camera,
                           const Headers& headers) {
  auto status =
      nlohmann::json::parse(fetch(url + "api/status", "GET", headers).body, nullptr, false);
  return status.is_object() ? entryNamed(status["streams"], camera) : nullptr;
}

uint64_t framesOf(const std::string& url, const std::string& camera, const Headers& headers) {
  auto stream = streamEntry(url, camera, headers);
  return stream.is_object() ? stream["frames"].get<uint64_t>() : 0;
}

void expectSigintEndsItWithinThreeSeconds(RecorderProcess& recorder,
                                          const std::function<void()>& meanwhile) {
  using Clock = std::chrono::steady_clock;
  auto signalled = Clock::now();
  recorder.signal(SIGINT);
  if (meanwhile) meanwhile();
  auto code = recorder.waitExit(patience(std::chrono::milliseconds(3000)));
  ASSERT_TRUE(code.has_value()) << "still running 3 s after SIGINT" << recorder.log();
  EXPECT_EQ(*code, 0) << recorder.log();
  EXPECT_LT(Clock::now() - signalled, patience(std::chrono::milliseconds(3000)));
}

}  // namespace wircam::testing
