// Distinct JPEG frames rendered by the follow scene, for tests that compare
// what arrives with what the simulator sent.
#pragma once

#include <cstdint>
#include <vector>

namespace wircam::testing {

const std::vector<std::vector<uint8_t>>& sceneFrames();
bool isSceneFrame(const std::vector<uint8_t>& frame);

}  // namespace wircam::testing
