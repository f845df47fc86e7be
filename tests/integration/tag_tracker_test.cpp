// ROI tracking against full-frame detection on the simulator's sequences.
#include "tag_tracker.h"

#include <gtest/gtest.h>
#include <turbojpeg.h>

#include <set>

#include "follow_scene.h"

namespace wircam::vision {
namespace {

struct Frame {
  std::vector<uint8_t> gray;
  int width;
  int height;
};

std::vector<Frame> followSequence(int width, int height, int count) {
  auto scene = sim::FollowScene::create(
      {.width = width, .height = height, .tagIds = {0, 4, 8}, .path = sim::TargetPath::Circle});
  std::unique_ptr<void, decltype(&tjDestroy)> decoder(tjInitDecompress(), tjDestroy);
  std::vector<Frame> frames;
  for (int i = 0; i < count; ++i) {
    (*scene)->step(0.1, {});
    auto jpeg = (*scene)->renderJpeg(0);
    Frame f{std::vector<uint8_t>(static_cast<size_t>(width) * height), width, height};
    tjDecompress2(decoder.get(), jpeg.data(), jpeg.size(), f.gray.data(), width, width, height,
                  TJPF_GRAY, 0);
    frames.push_back(std::move(f));
  }
  return frames;
}

std::set<int> ids(const std::vector<TagDetection>& detections) {
  std::set<int> out;
  for (const auto& d : detections) out.insert(d.id);
  return out;
}

TEST(TagTracker, FindsTheSameTagsAsAFullFrameSearch) {
  for (auto [width, height] : {std::pair{352, 288}, std::pair{1280, 720}}) {
    auto frames = followSequence(width, height, 40);
    auto full = TagDetector::create({.quadDecimate = 1});
    auto tracker = TagTracker::create({.quadDecimate = 1});
    ASSERT_TRUE(full.has_value() && tracker.has_value());
    for (size_t i = 0; i < frames.size(); ++i) {
      GrayView view{frames[i].gray.data(), width, height, width};
      auto expected = full->detect(view);
      auto got = tracker->detect(view);
      ASSERT_FALSE(expected.empty());
      EXPECT_EQ(ids(got), ids(expected)) << width << "x" << height << " frame " << i;
      for (const auto& g : got)
        for (const auto& e : expected)
          if (g.id == e.id) {
            EXPECT_NEAR(g.center.x, e.center.x, 0.5);  // same pixels, window or not
            EXPECT_NEAR(g.center.y, e.center.y, 0.5);
          }
    }
    EXPECT_GT(tracker->stats().windowSearches, tracker->stats().fullSearches);
  }
}

TEST(TagTracker, SearchesTheWholeFrameWhenATagIsLost) {
  auto frames = followSequence(352, 288, 3);
  auto tracker = TagTracker::create({.quadDecimate = 1});
  GrayView view{frames[0].gray.data(), 352, 288, 352};
  ASSERT_FALSE(tracker->detect(view).empty());
  std::vector<uint8_t> blank(352 * 288, 128);
  EXPECT_TRUE(tracker->detect({blank.data(), 352, 288, 352}).empty());
  EXPECT_EQ(tracker->stats().fallbacks, 1u);
  EXPECT_FALSE(tracker->detect(view).empty());
}

TEST(TagDetector, RefusesAHammingDistanceThatWouldTakeGigabytes) {
  EXPECT_TRUE(TagDetector::create({.maxHamming = kMaxHamming}));
  auto refused = TagDetector::create({.maxHamming = 3});
  ASSERT_FALSE(refused);
  EXPECT_NE(refused.error().find("0..2"), std::string::npos) << refused.error();
}

TEST(TagTracker, WithoutTrackingEveryFrameIsAFullSearch) {
  // fullFrameInterval 1 is apriltagdetect without roi-tracking: no window
  // detector is built, and no window is ever searched.
  auto tracker = TagTracker::create({.quadDecimate = 1}, {.fullFrameInterval = 1});
  ASSERT_TRUE(tracker);
  for (const auto& frame : followSequence(352, 288, 5)) {
    GrayView view{frame.gray.data(), frame.width, frame.height, frame.width};
    EXPECT_FALSE(tracker->detect(view).empty());
  }
  EXPECT_EQ(tracker->stats().fullSearches, 5u);
  EXPECT_EQ(tracker->stats().windowSearches, 0u);
}

}  // namespace
}  // namespace wircam::vision
