// A segment's sidecar: named after the video, created when asked, lines
// appended (a reopened sidecar keeps what it had), failures reported.
#include "record/telemetry_log.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>

namespace {

namespace fs = std::filesystem;
using wircam::recorder::TelemetryLog;

std::string read(const fs::path& file) {
  std::ifstream in(file);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

TEST(TelemetryLog, IsNamedAfterItsVideo) {
  EXPECT_EQ(TelemetryLog::pathFor("/rec/rover-cam0-20261122T120000Z.mkv"),
            "/rec/rover-cam0-20261122T120000Z.jsonl");
  EXPECT_EQ(TelemetryLog::pathFor("/rec.d/segment"), "/rec.d/segment.jsonl");
}

TEST(TelemetryLog, AppendsLinesAndKeepsThemAcrossReopening) {
  auto video = fs::temp_directory_path() / ("telemetry-log-" + std::to_string(getpid()) + ".mkv");
  auto path = TelemetryLog::pathFor(video);
  fs::remove(path);
  {
    TelemetryLog log(video);
    EXPECT_TRUE(log.create());
    EXPECT_TRUE(fs::exists(path));
    EXPECT_TRUE(log.write(R"({"a":1})"));
  }
  {
    TelemetryLog late(video);  // a late line for a closed segment
    EXPECT_TRUE(late.write(R"({"b":2})"));
  }
  EXPECT_EQ(read(path), "{\"a\":1}\n{\"b\":2}\n");
  fs::remove(path);
}

TEST(TelemetryLog, SaysWhenItCannotWrite) {
  TelemetryLog log("/no/such/folder/video.mkv");
  EXPECT_FALSE(log.create());
  EXPECT_FALSE(log.write("{}"));
}

}  // namespace
