// Retention: the oldest finished segments go first, with their sidecars,
// never an open one, and only until the limit holds.
#include "record/retention.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>

#include "record/disk_guard.h"
#include "temp_folder_test.h"

namespace {

namespace fs = std::filesystem;
using namespace wircam::recorder;

class RetentionTest : public wircam::testing::TempFolderTest {
 protected:
  // A segment of `bytes` (and a 100-byte sidecar) written `age` seconds ago.
  std::string segment(const std::string& name, size_t bytes, int age) {
    auto video = folder_ / name;
    std::ofstream(video) << std::string(bytes, 'v');
    std::ofstream(fs::path(video).replace_extension(".jsonl")) << std::string(100, 'j');
    fs::last_write_time(video, fs::file_time_type::clock::now() - std::chrono::seconds(age));
    return video.string();
  }
};

TEST_F(RetentionTest, DeletesTheOldestUntilUnderTheCapButNeverAnOpenSegment) {
  std::vector<std::string> logged;
  Retention retention(folder_, {.maxBytes = 2500},
                      [&](const std::string& l) { logged.push_back(l); });
  auto oldest = segment("a.mkv", 1000, 40);
  auto older = segment("b.mkv", 1000, 30);
  auto newer = segment("c.mp4", 1000, 20);
  auto open = segment("d.mkv", 1000, 50);                          // the oldest, but being written
  std::ofstream(folder_ / "notes.txt") << std::string(5000, 'n');  // not a recording
  auto deleted = retention.enforce({open});
  // 4400 bytes of recordings: two of the finished ones go, oldest first.
  EXPECT_EQ(deleted, (std::vector<std::string>{oldest, older}));
  EXPECT_FALSE(fs::exists(oldest));
  EXPECT_FALSE(fs::exists(fs::path(oldest).replace_extension(".jsonl")));
  EXPECT_TRUE(fs::exists(newer));
  EXPECT_TRUE(fs::exists(open));
  EXPECT_TRUE(fs::exists(folder_ / "notes.txt"));
  EXPECT_EQ(logged.size(), 2u);
  EXPECT_NE(logged[0].find("over --max-bytes"), std::string::npos);
}

TEST_F(RetentionTest, WithoutLimitsNothingIsDeleted) {
  Retention retention(folder_, {}, [](const std::string&) {});
  auto kept = segment("a.mkv", 1000, 40);
  EXPECT_FALSE(retention.active());
  EXPECT_TRUE(retention.enforce({}).empty());
  EXPECT_TRUE(fs::exists(kept));
}

TEST_F(RetentionTest, SegmentsOlderThanTheMaxAgeGoUnlessTheirEventsKeepThemLonger) {
  using std::chrono::hours;
  std::vector<std::string> logged;
  Retention retention(folder_, {.maxAge = hours(24), .keepEvents = hours(24 * 7)},
                      [&](const std::string& l) { logged.push_back(l); });
  auto young = segment("young.mkv", 100, 0);
  auto quiet = segment("quiet.mkv", 100, 0);
  auto tagged = segment("tagged.mkv", 100, 0);
  auto steered = segment("steered.mkv", 100, 0);
  auto ancient = segment("ancient.mkv", 100, 0);
  auto open = segment("open.mkv", 100, 0);
  auto sidecar = [](const std::string& video, const std::string& lines) {
    std::ofstream(fs::path(video).replace_extension(".jsonl")) << lines;
  };
  sidecar(quiet, R"({"type":"detections","detections":[],"pts":0})"
                 "\n"
                 R"({"type":"control","steering-pulse":1500,"throttle-pulse":1500,"pts":0})"
                 "\n");
  sidecar(tagged, R"({"type":"detections","detections":[{"id":3}],"pts":0})"
                  "\n");
  sidecar(steered, R"({"type":"control","steering-pulse":1620,"throttle-pulse":1500,"pts":0})"
                   "\n");
  sidecar(ancient, R"({"type":"detections","detections":[{"id":3}],"pts":0})"
                   "\n");
  // Time is a parameter: "now" is three days after they were written, and
  // the ancient one was written ten days before that.
  auto written = fs::file_time_type::clock::now();
  for (const auto& video : {young, quiet, tagged, steered, open})
    fs::last_write_time(video, written);
  fs::last_write_time(ancient, written - hours(24 * 10));
  fs::last_write_time(young, written + hours(24 * 3));
  auto now = std::chrono::file_clock::to_sys(written) + hours(24 * 3);
  auto deleted = retention.enforce({open}, now);
  std::sort(deleted.begin(), deleted.end());
  EXPECT_EQ(deleted, (std::vector<std::string>{ancient, quiet}));
  for (const auto& kept : {young, tagged, steered, open}) EXPECT_TRUE(fs::exists(kept)) << kept;
  ASSERT_EQ(logged.size(), 2u);
  EXPECT_NE(logged[0].find("older than --max-age"), std::string::npos);
  // A week later the ones kept for their events go too, and the young one
  // (a quiet day old by then); never the open one.
  deleted = retention.enforce({open}, now + hours(24 * 7));
  std::sort(deleted.begin(), deleted.end());
  EXPECT_EQ(deleted, (std::vector<std::string>{steered, tagged, young}));
  EXPECT_TRUE(fs::exists(open));
}

TEST(RetentionDuration, ReadsDaysHoursMinutesAndSeconds) {
  using std::chrono::seconds;
  EXPECT_EQ(parseDuration("7d"), seconds(7 * 86400));
  EXPECT_EQ(parseDuration("12h"), seconds(12 * 3600));
  EXPECT_EQ(parseDuration("30m"), seconds(1800));
  EXPECT_EQ(parseDuration("90s"), seconds(90));
  EXPECT_EQ(parseDuration("90"), seconds(90));
  EXPECT_EQ(parseDuration("1.5h"), seconds(5400));
  EXPECT_EQ(parseDuration("2w"), seconds(14 * 86400));
  for (const char* bad : {"", "d", "7 days", "-1d", "7y", "1e300d", "nan", "7dd"})
    EXPECT_FALSE(parseDuration(bad).has_value()) << bad;
}

TEST(DiskGuard, KeepsAMebibyteAndFourSecondsOfWriting) {
  EXPECT_EQ(DiskGuard::reserveFor(0), 1u << 20);
  EXPECT_EQ(DiskGuard::reserveFor(1000000), (1u << 20) + 4000000u);
  DiskGuard guard(fs::temp_directory_path());
  ASSERT_GT(guard.free(), 2u << 20);  // the test machine has room
  EXPECT_FALSE(guard.nearlyFull(0));
  EXPECT_TRUE(guard.nearlyFull(guard.free() / 4));  // 4 s of it would not fit
  EXPECT_EQ(freeBytes("/no/such/folder"), UINT64_MAX);
}

}  // namespace
