#include "scene_frames.h"

#include <algorithm>

#include "follow_scene.h"

namespace wircam::testing {

const std::vector<std::vector<uint8_t>>& sceneFrames() {
  static const auto frames = [] {
    auto scene = sim::FollowScene::create({.path = sim::TargetPath::Line});
    std::vector<std::vector<uint8_t>> all;
    for (int i = 0; i < 6; ++i) {
      (*scene)->step(0.2, {});
      all.push_back((*scene)->renderJpeg(0));
    }
    return all;
  }();
  return frames;
}

bool isSceneFrame(const std::vector<uint8_t>& frame) {
  const auto& all = sceneFrames();
  return std::find(all.begin(), all.end(), frame) != all.end();
}

}  // namespace wircam::testing
