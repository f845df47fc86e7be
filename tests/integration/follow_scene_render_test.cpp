// The simulator's pictures must be what it says they are: the AprilTag
// library, run on a rendered and JPEG-encoded frame, finds the target tag at
// the corners the scene reports.
#include <gtest/gtest.h>
#include <turbojpeg.h>

#include <cmath>

#include "follow_scene.h"
#include "tag_detector.h"

namespace wircam::sim {
namespace {

std::vector<uint8_t> decodeGray(const std::vector<uint8_t>& jpeg, int& width, int& height) {
  std::unique_ptr<void, decltype(&tjDestroy)> decoder(tjInitDecompress(), tjDestroy);
  int subsampling = 0, colorspace = 0;
  EXPECT_EQ(tjDecompressHeader3(decoder.get(), jpeg.data(), jpeg.size(), &width, &height,
                                &subsampling, &colorspace),
            0);
  std::vector<uint8_t> gray(static_cast<size_t>(width) * height);
  EXPECT_EQ(tjDecompress2(decoder.get(), jpeg.data(), jpeg.size(), gray.data(), width, width,
                          height, TJPF_GRAY, 0),
            0);
  return gray;
}

void expectTagAtReportedCorners(FollowScene& scene) {
  auto views = scene.tagViews();
  ASSERT_TRUE(views[0].visible);
  int width = 0, height = 0;
  auto gray = decodeGray(scene.renderJpeg(0), width, height);
  EXPECT_EQ(width, scene.config().width);

  auto detector = vision::TagDetector::create({.family = scene.config().family, .quadDecimate = 1});
  ASSERT_TRUE(detector.has_value());
  auto found = detector->detect({gray.data(), width, height, width});
  ASSERT_EQ(found.size(), 1u);
  EXPECT_EQ(found[0].id, views[0].id);
  for (size_t i = 0; i < 4; ++i) {
    EXPECT_NEAR(found[0].corners[i].x, views[0].corners[i].x, 1.0) << "corner " << i;
    EXPECT_NEAR(found[0].corners[i].y, views[0].corners[i].y, 1.0) << "corner " << i;
  }
}

TEST(FollowSceneRender, TagIsDetectedAtTheReportedCornersAtTheStart) {
  auto scene = FollowScene::create({.path = TargetPath::Still});
  ASSERT_TRUE(scene.has_value()) << scene.error();
  (*scene)->step(0, {});
  expectTagAtReportedCorners(**scene);
}

TEST(FollowSceneRender, TagIsDetectedAtTheReportedCornersWhenSeenAtAnAngle) {
  auto scene = FollowScene::create({.width = 1280, .height = 720, .path = TargetPath::Circle});
  ASSERT_TRUE(scene.has_value()) << scene.error();
  for (int i = 0; i < 30; ++i) (*scene)->step(0.1, {});  // the target turns away, the car stays
  EXPECT_GT(std::abs((*scene)->target().theta), 0.2);
  expectTagAtReportedCorners(**scene);
}

TEST(FollowSceneRender, OtherFamiliesRenderToo) {
  for (const char* family : {"tag25h9", "tagStandard41h12"}) {
    auto scene = FollowScene::create({.family = family, .tagIds = {3}, .path = TargetPath::Still});
    ASSERT_TRUE(scene.has_value()) << scene.error();
    (*scene)->step(0, {});
    expectTagAtReportedCorners(**scene);
  }
}

TEST(FollowSceneRender, ThrottleDrivesTheCarAndSteeringTurnsIt) {
  auto scene = FollowScene::create({.path = TargetPath::Still});
  ASSERT_TRUE(scene.has_value());
  wirc::ChannelOutputs outputs;
  outputs.failsafe = false;
  outputs.pulses[1] = 1800;  // forward
  outputs.pulses[0] = 2000;  // full left
  for (int i = 0; i < 20; ++i) (*scene)->step(0.05, outputs);
  EXPECT_GT((*scene)->car().x, 0.2);
  EXPECT_GT((*scene)->car().theta, 0.1);
  EXPECT_LT((*scene)->bearingDeg(), 0);  // the target is now to the right
}

TEST(FollowSceneRender, RejectsATagIdOutsideTheFamily) {
  auto scene = FollowScene::create({.family = "tag16h5", .tagIds = {100}});
  ASSERT_FALSE(scene.has_value());
  EXPECT_NE(scene.error().find("tag16h5"), std::string::npos);
}

}  // namespace
}  // namespace wircam::sim
