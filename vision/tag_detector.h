// AprilTag detection over a grayscale image: the AprilTag 3 detector with its
// options, returning plain structs so no library pointer leaves this file.
#pragma once

#include <array>
#include <memory>
#include <optional>
#include <string>
#include <type_traits>
#include <vector>

#include "common/expected.h"
#include "tag_family.h"

struct apriltag_detector;

namespace wircam::vision {

struct Point2 {
  double x = 0;
  double y = 0;
};

// Tag pose in the camera frame (x right, y down, z forward, metres); yaw is
// the tag's rotation about the camera's vertical axis, radians.
struct TagPose {
  double x = 0;
  double y = 0;
  double z = 0;
  double yaw = 0;
};

struct TagDetection {
  int id = 0;
  std::string family;
  int hamming = 0;
  double margin = 0;  // decision margin: higher is surer
  Point2 center;
  std::array<Point2, 4> corners;       // in the library's order, input pixels
  std::array<double, 9> homography{};  // row-major, tag [-1,1]² → image
  std::optional<TagPose> pose;         // when the camera and tag size are known
};

// What pose estimation needs: the tag's edge and the camera's intrinsics.
struct PoseConfig {
  double tagSize = 0;  // m, edge of the black border square
  double fx = 0, fy = 0, cx = 0, cy = 0;
};

// The most bit errors a detector corrects: 3 would need a decoding table of
// gigabytes (apriltag.h's own warning; 2.4 GB measured).
inline constexpr int kMaxHamming = 2;

struct DetectorOptions {
  std::string family = "tag36h11";
  float quadDecimate = 2.0f;  // the library's; the element defaults to 1 (see its blurb)
  float quadSigma = 0.0f;
  int threads = 1;
  bool refineEdges = true;
  double decodeSharpening = 0.25;
  int maxHamming = 1;      // detections with more bit errors are dropped
  double minMargin = 0.0;  // detections less sure than this are dropped
  std::optional<PoseConfig> pose;
};

// A grayscale image in memory the caller owns.
struct GrayView {
  const uint8_t* data = nullptr;
  int width = 0;
  int height = 0;
  int stride = 0;
};

// Move-only: the underlying detector is not thread-safe, so two copies may
// not share it.
class TagDetector {
 public:
  static Expected<TagDetector, std::string> create(const DetectorOptions& options);

  // `image` may be a window into a larger frame whose top-left corner sits
  // at `origin`: the detections are given in the larger frame's pixels.
  std::vector<TagDetection> detect(const GrayView& image, Point2 origin = {});
  const DetectorOptions& options() const { return options_; }

 private:
  TagDetector(DetectorOptions options, TagFamily family);

  DetectorOptions options_;
  TagFamily family_;
  std::unique_ptr<apriltag_detector, void (*)(apriltag_detector*)> detector_;
};
static_assert(!std::is_copy_constructible_v<TagDetector>);

}  // namespace wircam::vision
