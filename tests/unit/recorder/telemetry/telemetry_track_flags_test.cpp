// Marking the telemetry track leaves anything that is not a recording's
// header exactly as it was (the real files are checked with ffprobe in
// tests/recorder/segment_files_test.cpp).
#include "telemetry/telemetry_track_flags.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <fstream>
#include <sstream>

namespace {

namespace fs = std::filesystem;
using wircam::recorder::markTelemetryTrack;

std::string contentsOf(const fs::path& file) {
  std::ifstream in(file, std::ios::binary);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

TEST(TelemetryTrackFlags, LeavesOtherFilesUntouched) {
  auto base = fs::temp_directory_path() / ("track-flags-" + std::to_string(getpid()));
  // Random bytes, a truncated EBML header, and an MP4 with no text track.
  std::string garbage(5000, '\xff');
  std::string ebml("\x1a\x45\xdf\xa3\x93\x42\x86\x81", 8);
  std::string mp4("\x00\x00\x00\x10moovJUNKJUNK", 16);
  for (const auto& [name, bytes] : {std::pair{"a.mkv", garbage}, std::pair{"b.mkv", ebml},
                                    std::pair{"c.mp4", mp4}, std::pair{"d.mp4", garbage}}) {
    auto file = fs::path(base.string() + name);
    std::ofstream(file, std::ios::binary) << bytes;
    EXPECT_FALSE(markTelemetryTrack(file)) << name;
    EXPECT_EQ(contentsOf(file), bytes) << name;
    fs::remove(file);
  }
  EXPECT_FALSE(markTelemetryTrack(base.string() + "missing.mkv"));
}

}  // namespace
