// The thread that writes a filesystem's recorded files: bytes land at the
// offsets the muxer gave them, in order (a seek back overwrites), a
// camera's budget counts what waits, a full disk is the file's error, and
// the cameras of one filesystem share one writer.
#include "camera/disk_writer.h"

#include <gst/gst.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <filesystem>
#include <fstream>
#include <future>
#include <iterator>
#include <string>
#include <thread>
#include <vector>

namespace {

namespace fs = std::filesystem;
using namespace wircam::recorder;

GstBuffer* bytesOf(const std::string& text) {
  return gst_buffer_new_memdup(text.data(), text.size());
}

std::string contentOf(const fs::path& file) {
  std::ifstream in(file, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

class DiskWriterTest : public ::testing::Test {
 protected:
  void SetUp() override {
    gst_init(nullptr, nullptr);
    folder_ = fs::temp_directory_path() / ("disk-writer-" + std::to_string(getpid()));
    fs::create_directories(folder_);
  }
  void TearDown() override { fs::remove_all(folder_); }

  // Hands `text` over at `offset`, as the sink does.
  void write(DiskWriter& writer, const std::shared_ptr<DiskWriter::File>& file, uint64_t offset,
             const std::string& text) {
    GstBuffer* bytes = bytesOf(text);
    writer.write(file, offset, bytes, budget_);
    gst_buffer_unref(bytes);
  }

  fs::path folder_;
  std::shared_ptr<DiskBudget> budget_ = std::make_shared<DiskBudget>(100);
};

TEST_F(DiskWriterTest, BytesLandAtTheirOffsetsInOrderAndASeekBackOverwrites) {
  auto writer = DiskWriter::of(folder_.string());
  ASSERT_TRUE(writer) << writer.error();
  auto file = DiskWriter::open((folder_ / "a.mkv").string());
  ASSERT_TRUE(file);
  write(**writer, *file, 0, "header--");
  write(**writer, *file, 8, "frame1");
  write(**writer, *file, 14, "frame2");
  write(**writer, *file, 0, "HEADER");  // the muxer's end: its size and index
  EXPECT_EQ((*writer)->close(*file), 0);
  EXPECT_EQ(contentOf(folder_ / "a.mkv"), "HEADER--frame1frame2");
  EXPECT_EQ(budget_->waiting(), 0u);
}

TEST_F(DiskWriterTest, AHeldDiskKeepsTheBytesInTheCamerasBudgetUntilItWritesThem) {
  auto writer = DiskWriter::of(folder_.string());
  ASSERT_TRUE(writer);
  auto file = DiskWriter::open((folder_ / "b.mkv").string());
  ASSERT_TRUE(file);
  (*writer)->hold();
  write(**writer, *file, 0, std::string(60, 'x'));
  EXPECT_FALSE(budget_->full());
  write(**writer, *file, 60, std::string(60, 'y'));
  EXPECT_EQ(budget_->waiting(), 120u);
  EXPECT_TRUE(budget_->full()) << "past its bound the camera drops";
  (*writer)->release();
  EXPECT_EQ((*writer)->close(*file), 0);
  EXPECT_EQ(budget_->waiting(), 0u);
  EXPECT_EQ(fs::file_size(folder_ / "b.mkv"), 120u);
}

TEST_F(DiskWriterTest, AFullDiskIsTheFilesErrorAndItsCloseSaysSo) {
  auto writer = DiskWriter::of(folder_.string());
  ASSERT_TRUE(writer);
  // /dev/full: a device that takes no byte, as a full disk.
  if (!fs::exists("/dev/full")) GTEST_SKIP() << "no /dev/full on this machine";
  auto file = DiskWriter::open("/dev/full");
  ASSERT_TRUE(file);
  write(**writer, *file, 0, "frame");
  EXPECT_EQ((*writer)->close(*file), ENOSPC);
  EXPECT_EQ(DiskWriter::errorOf(**file), ENOSPC);
  EXPECT_EQ(budget_->waiting(), 0u) << "what failed is no longer waiting";
}

// A file cut off after its camera's pipeline is gone ends on the writer's
// thread, and what it lets go of there (its sink) may have held the last
// reference to the writer: the writer must not end with it (a thread
// cannot join itself; the recorder aborted).
TEST_F(DiskWriterTest, AFileEndingOnTheWritersThreadLetsGoOfTheWriterWithoutEndingIt) {
  auto writer = DiskWriter::of(folder_.string());
  ASSERT_TRUE(writer);
  DiskWriter* shared = writer->get();
  auto file = DiskWriter::open((folder_ / "e.mkv").string());
  ASSERT_TRUE(file);
  shared->hold();
  write(*shared, *file, 0, "last frame");
  std::promise<int> ended;
  shared->closeWhenWritten(*file, [heldBySink = *writer, &ended](int error) mutable {
    heldBySink.reset();
    ended.set_value(error);
  });
  writer->reset();  // the camera's pipeline is gone
  shared->release();
  auto end = ended.get_future();
  ASSERT_EQ(end.wait_for(std::chrono::seconds(10)), std::future_status::ready);
  EXPECT_EQ(end.get(), 0);
  EXPECT_EQ(contentOf(folder_ / "e.mkv"), "last frame");
  auto again = DiskWriter::of(folder_.string());
  ASSERT_TRUE(again);
  EXPECT_EQ(again->get(), shared) << "the next camera on this filesystem takes up the same writer";
}

// The lanes are written in the order they got writes: once a write on a
// lane of its own is done, so is every write handed over before it.
TEST_F(DiskWriterTest, AWriteOnAFreshLaneIsDoneAfterEveryWriteHandedOverBeforeIt) {
  auto writer = DiskWriter::of(folder_.string());
  ASSERT_TRUE(writer);
  auto video = DiskWriter::open((folder_ / "video.mkv").string());
  auto marker = DiskWriter::open((folder_ / "marker").string());
  ASSERT_TRUE(video && marker);
  auto camera = std::make_shared<DiskBudget>(1 << 30);
  (*writer)->hold();
  constexpr size_t kPiece = 1 << 16, kPieces = 64;  // long enough to be caught writing
  for (size_t piece = 0; piece < kPieces; ++piece) {
    GstBuffer* bytes = bytesOf(std::string(kPiece, 'v'));
    (*writer)->write(*video, piece * kPiece, bytes, camera);
    gst_buffer_unref(bytes);
  }
  write(**writer, *marker, 0, "m");
  (*writer)->release();
  EXPECT_EQ((*writer)->close(*marker), 0);
  EXPECT_EQ(camera->waiting(), 0u) << "the marker was written before the video handed over first";
  EXPECT_EQ((*writer)->close(*video), 0);
  EXPECT_EQ(fs::file_size(folder_ / "video.mkv"), kPiece * kPieces);
}

// Each camera hands over on its own lane, none locking another's: the
// lanes listed at once, taken and listed again while the writer runs, lose
// and reorder nothing.
TEST_F(DiskWriterTest, ManyCamerasHandingOverAtOnceGetEveryByteInOrder) {
  auto writer = DiskWriter::of(folder_.string());
  ASSERT_TRUE(writer);
  constexpr int kCameras = 16;
  constexpr int kPieces = 400;
  std::vector<std::shared_ptr<DiskBudget>> budgets;
  std::vector<std::shared_ptr<DiskWriter::File>> files;
  for (int camera = 0; camera < kCameras; ++camera) {
    budgets.push_back(std::make_shared<DiskBudget>(1 << 20));
    auto file = DiskWriter::open((folder_ / (std::to_string(camera) + ".mkv")).string());
    ASSERT_TRUE(file);
    files.push_back(*file);
  }
  std::vector<std::thread> cameras;
  for (int camera = 0; camera < kCameras; ++camera)
    cameras.emplace_back([&, camera] {
      for (int piece = 0; piece < kPieces; ++piece) {
        GstBuffer* bytes = bytesOf(std::string(1, static_cast<char>('a' + piece % 26)));
        (*writer)->write(files[camera], piece, bytes, budgets[camera]);
        gst_buffer_unref(bytes);
        if (piece % 50 == 0) std::this_thread::yield();
      }
    });
  for (auto& camera : cameras) camera.join();
  std::string expected;
  for (int piece = 0; piece < kPieces; ++piece) expected += static_cast<char>('a' + piece % 26);
  for (int camera = 0; camera < kCameras; ++camera) {
    EXPECT_EQ((*writer)->close(files[camera]), 0);
    EXPECT_EQ(contentOf(folder_ / (std::to_string(camera) + ".mkv")), expected) << camera;
    EXPECT_EQ(budgets[camera]->waiting(), 0u) << camera;
  }
}

TEST_F(DiskWriterTest, TheCamerasOfOneFilesystemShareOneWriterAndAMissingFolderIsAnError) {
  fs::create_directories(folder_ / "other");
  auto one = DiskWriter::of(folder_.string());
  auto two = DiskWriter::of((folder_ / "other").string());
  ASSERT_TRUE(one && two);
  EXPECT_EQ(one->get(), two->get());
  auto missing = DiskWriter::of((folder_ / "missing").string());
  ASSERT_FALSE(missing);
  EXPECT_NE(missing.error().find("missing"), std::string::npos) << missing.error();
  auto unopened = DiskWriter::open((folder_ / "missing" / "c.mkv").string());
  ASSERT_FALSE(unopened);
  EXPECT_EQ(unopened.error(), ENOENT);
}

}  // namespace
