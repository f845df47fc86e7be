// A full disk: the recorder stops while the open segments can still be
// finished, says why, and leaves every segment playable. The disk is a
// small tmpfs in a private mount namespace (unprivileged, through a user
// namespace), so the test never fills a real file system.
#include <gtest/gtest.h>

#include <chrono>

#include "recorder_process.h"
#include "simulated_device.h"

namespace {

namespace fs = std::filesystem;
using namespace wircam::testing;

constexpr int kNoNamespace = 125;
constexpr int kExitDiskFull = 3;

struct SmallDisk {
  fs::path mountPoint, saved;
  explicit SmallDisk(const std::string& name) {
    auto base = fs::temp_directory_path() / (name + "-" + std::to_string(getpid()));
    mountPoint = base.string() + "-disk";
    saved = base.string() + "-saved";
    fs::remove_all(saved);
  }
  ~SmallDisk() {
    fs::remove_all(saved);
    fs::remove_all(mountPoint);
  }

  // Runs the recorder with a tmpfs of `size` at mountPoint (after `setup`,
  // shell run in it), then copies what it left into `saved` (the tmpfs goes
  // with the namespace).
  std::vector<std::string> wrapper(const char* size, const std::string& setup = "true") const {
    return {"unshare",
            "--mount",
            "--map-root-user",
            "sh",
            "-c",
            "m=$1; s=$2; mkdir -p \"$m\" \"$s\" && mount -t tmpfs -o size=$0 wirc-test \"$m\" "
            "|| exit 125; (cd \"$m\" && eval \"$3\") || exit 126; shift 3; \"$@\"; code=$?; "
            "cp -a \"$m\"/. \"$s\"/; exit $code",
            size,
            mountPoint.string(),
            saved.string(),
            setup};
  }

  std::vector<fs::path> videos() const {
    std::vector<fs::path> found;
    for (const auto& entry : fs::directory_iterator(saved))
      if (entry.path().extension() == ".mkv") found.push_back(entry.path());
    std::sort(found.begin(), found.end());
    return found;
  }
};

TEST(WircRecorderDiskFull, FinishesEverySegmentAndExitsThree) {
  auto device = startSequenceDevice(0, 30);
  ASSERT_TRUE(device);
  SmallDisk disk("wirc-disk-full");
  auto start = std::chrono::steady_clock::now();
  RecorderProcess recorder(0,
                           {"--device", "127.0.0.1:" + std::to_string(device->port()), "--out",
                            disk.mountPoint.string(), "--segment", "2", "--duration", "60"},
                           disk.wrapper("4m"));
  int code = recorder.wait();
  if (code == kNoNamespace) GTEST_SKIP() << "no mount namespace here: " << recorder.log();
  ASSERT_EQ(code, kExitDiskFull) << recorder.log();
  EXPECT_LT(std::chrono::steady_clock::now() - start, std::chrono::seconds(40));
  EXPECT_NE(recorder.log().find("is full"), std::string::npos) << recorder.log();

  auto videos = disk.videos();
  ASSERT_GE(videos.size(), 2u);
  int frames = 0;
  for (const auto& video : videos) {
    EXPECT_TRUE(GST_CLOCK_TIME_IS_VALID(durationOf(video))) << video;
    auto contents = contentsOf(video);
    EXPECT_GT(contents.frames, 0) << video;
    EXPECT_TRUE(contents.monotonic) << video;
    frames += contents.frames;
  }
  // Nothing that was recorded is lost: every frame delivered is in a file.
  EXPECT_GE(static_cast<uint64_t>(frames) + 3, device->stats().framesSent);
}

// A disk left full by an old segment: --max-age prunes it at start-up (a
// removal needs no room), and the recording goes on.
TEST(WircRecorderDiskFull, AnOldSegmentOnAFullDiskIsPrunedByAgeAndRecordingGoesOn) {
  auto device = startSequenceDevice();
  ASSERT_TRUE(device);
  SmallDisk disk("wirc-disk-aged");
  RecorderProcess recorder(
      0,
      {"--device", "127.0.0.1:" + std::to_string(device->port()), "--out", disk.mountPoint.string(),
       "--max-age", "1d", "--duration", "3"},
      disk.wrapper("2m",
                   "dd if=/dev/zero of=old-cam0-20260101T000000Z.mkv bs=1k count=1900 "
                   "2>/dev/null; touch -d '10 days ago' old-cam0-20260101T000000Z.mkv"));
  int code = recorder.wait();
  if (code == kNoNamespace) GTEST_SKIP() << "no mount namespace here: " << recorder.log();
  EXPECT_EQ(code, 0) << recorder.log();
  EXPECT_NE(recorder.log().find("deleted old-cam0-20260101T000000Z.mkv (older than --max-age)"),
            std::string::npos)
      << recorder.log();
  auto videos = disk.videos();
  ASSERT_EQ(videos.size(), 1u);
  EXPECT_GT(contentsOf(videos[0]).frames, 10);
}

TEST(WircRecorderDiskFull, StopsAtOnceWhenThereIsNoRoomToStart) {
  auto device = startSequenceDevice();
  ASSERT_TRUE(device);
  SmallDisk disk("wirc-disk-none");
  RecorderProcess recorder(0,
                           {"--device", "127.0.0.1:" + std::to_string(device->port()), "--out",
                            disk.mountPoint.string(), "--duration", "30"},
                           disk.wrapper("512k"));
  int code = recorder.wait();
  if (code == kNoNamespace) GTEST_SKIP() << "no mount namespace here: " << recorder.log();
  EXPECT_EQ(code, kExitDiskFull) << recorder.log();
  EXPECT_NE(recorder.log().find("is full"), std::string::npos) << recorder.log();
}

}  // namespace
