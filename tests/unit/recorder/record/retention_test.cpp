// Retention: the oldest finished segments go first, with their sidecars,
// never an open one, and only until the limit holds.
#include "record/retention.h"

#include <gtest/gtest.h>

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
