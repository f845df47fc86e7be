// The recording index: entries in time order, saved whole, read back, and
// reconciled with the folder (files it lacks read in, deleted ones dropped).
#include "record/recording_index.h"

#include <gtest/gtest.h>

#include <fstream>

#include "temp_folder_test.h"

namespace {

namespace fs = std::filesystem;
using wircam::recorder::IndexEntry;
using wircam::recorder::parseSegmentName;
using wircam::recorder::RecordingIndex;

class RecordingIndexTest : public wircam::testing::TempFolderTest {
 protected:
  void touch(const std::string& name) { std::ofstream(folder_ / name) << "video"; }
};

IndexEntry entry(const std::string& file, const std::string& start) {
  return {.camera = "rover-cam0",
          .file = file,
          .startUtc = start,
          .durationSeconds = 5,
          .frames = 75,
          .bytes = 1000};
}

TEST_F(RecordingIndexTest, KeepsEntriesInTimeOrderAndReadsBackWhatItSaved) {
  RecordingIndex index(folder_);
  index.add(entry("b.mkv", "2026-11-22T12:00:05.000Z"));
  index.add(entry("a.mkv", "2026-11-22T12:00:00.000Z"));
  index.add(entry("b.mkv", "2026-11-22T12:00:05.000Z"));  // replaced, not doubled
  ASSERT_TRUE(index.save());
  RecordingIndex again(folder_);
  ASSERT_EQ(again.entries().size(), 2u);
  EXPECT_EQ(again.entries()[0].file, "a.mkv");
  EXPECT_EQ(again.entries()[1].frames, 75u);
  EXPECT_FALSE(fs::exists(folder_ / "index.json.tmp"));
}

TEST_F(RecordingIndexTest, ReconcilingAddsTheFilesItLacksAndDropsTheDeleted) {
  touch("rover-cam0-20261122T120000Z.mkv");
  touch("rover-cam0-20261122T120005Z.mkv");
  touch("open-cam0-20261122T120010Z.mkv");
  touch("notes.txt");
  RecordingIndex index(folder_);
  index.add(entry("gone.mkv", "2026-11-22T11:00:00.000Z"));
  std::vector<std::string> inspected;
  size_t added = index.reconcile(
      [&](const fs::path& file) -> std::optional<IndexEntry> {
        inspected.push_back(file.filename().string());
        auto name = parseSegmentName(file.filename().string());
        return entry(file.filename().string(), name->startUtc);
      },
      {(folder_ / "open-cam0-20261122T120010Z.mkv").string()});
  EXPECT_EQ(added, 2u);
  EXPECT_EQ(inspected, (std::vector<std::string>{"rover-cam0-20261122T120000Z.mkv",
                                                 "rover-cam0-20261122T120005Z.mkv"}));
  ASSERT_EQ(index.entries().size(), 2u);
  EXPECT_EQ(index.entries()[0].startUtc, "2026-11-22T12:00:00.000Z");
}

TEST_F(RecordingIndexTest, AnUnreadableIndexCountsAsMissing) {
  std::ofstream(folder_ / "index.json") << "{ not json";
  RecordingIndex index(folder_);
  EXPECT_TRUE(index.entries().empty());
}

TEST(SegmentName, GivesTheCameraAndTheUtcStart) {
  auto name = parseSegmentName("rover-cam1-20261122T143205Z-2.mp4");
  ASSERT_TRUE(name);
  EXPECT_EQ(name->camera, "rover-cam1");
  EXPECT_EQ(name->startUtc, "2026-11-22T14:32:05.000Z");
  EXPECT_EQ(parseSegmentName("rover-cam1-20261122T143205Z_3.mkv")->startUtc,
            "2026-11-22T14:32:05.000Z");
  EXPECT_FALSE(parseSegmentName("rover-cam1-20261122-143205-000.mkv"));
  EXPECT_FALSE(parseSegmentName("index.json"));
}

}  // namespace
