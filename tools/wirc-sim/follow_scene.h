// The simulator's default world: a car with a camera drives on a ground plane
// by the PCD it receives (kinematic bicycle model), and a target carrying an
// AprilTag moves on a path ahead of it. What the control loop sends changes
// what the camera sees next, so tag following can be tested closed-loop.
// The scene knows the truth and can write it per frame as JSONL.
#pragma once

#include <atomic>
#include <cstdio>
#include <memory>
#include <mutex>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "common/expected.h"
#include "devices/wirc/device.h"
#include "tag_family.h"

namespace wircam::sim {

enum class TargetPath { Still, Line, Circle };

struct FollowSceneConfig {
  int width = 352;
  int height = 288;
  int jpegQuality = 85;
  double horizontalFovDeg = 60;
  std::string family = "tag36h11";
  std::vector<int> tagIds = {0};  // the first rides on the target, the rest stand around
  double tagSize = 0.16;          // m, edge of the tag's black border square
  double cameraHeight = 0.25;     // m above the ground; the tag centre is as high
  TargetPath path = TargetPath::Circle;
  double targetSpeed = 0.3;     // m/s
  double circleRadius = 2.5;    // m
  double startDistance = 1.2;   // m from camera to target at the start
  double followDistance = 1.0;  // m, the set point the summary measures against
  bool carFixed = false;        // static scene: PCD moves nothing
  int steeringChannel = 1;      // 1-based, 2000 µs = full left
  int throttleChannel = 2;      // 1-based, 1500 µs neutral
  double wheelbase = 0.26;      // m
  double maxSteerRad = 0.5;
  double maxSpeed = 1.2;         // m/s at full throttle
  double throttleDeadband = 50;  // µs around neutral with no drive
  // Each frame shows, as kStampBits black or white blocks across its top
  // (most significant first), the wall clock's milliseconds since the epoch
  // (modulo 2^32) when it was drawn: what a viewer compares its own clock
  // with to measure latency (bench_live_latency).
  bool clockStamp = false;
};

inline constexpr int kStampBits = 32;

struct Pose2 {
  double x = 0;
  double y = 0;
  double theta = 0;  // rad, counter-clockwise from +x
};

// What the camera sees of one tag: its corners in pixels, in the order the
// AprilTag library reports them.
struct TagView {
  int id = 0;
  bool visible = false;  // all four corners in front of the camera and inside the frame
  std::array<cv::Point2d, 4> corners;
};

struct FollowSummary {
  uint64_t ticks = 0;
  // Over the ticks after the first 3 s of driving (on the device the scene
  // stands still until the first PCD arrives).
  double meanBearingDeg = 0;
  double maxBearingDeg = 0;
  double meanDistanceError = 0;  // |distance - followDistance|, m
  double maxDistanceError = 0;
  uint64_t measuredTicks = 0;
};

class FollowScene : public wirc::DeviceScene {
 public:
  static Expected<std::unique_ptr<FollowScene>, std::string> create(FollowSceneConfig config);
  ~FollowScene() override;

  // Writes one JSON object per tick to `path` (the truth file).
  std::optional<std::string> writeTruthTo(const std::string& path);

  void advance(wirc::DeviceClock::time_point now, const wirc::ChannelOutputs& outputs) override;
  std::vector<uint8_t> renderJpeg(int camera) override;

  // Hides the target's tag (as if something stood in front of it); safe to
  // call from any thread while the device renders.
  void setTargetHidden(bool hidden) { targetHidden_ = hidden; }

  // Advances by an explicit time step; advance() uses wall-clock time.
  void step(double seconds, const wirc::ChannelOutputs& outputs);
  cv::Mat renderBgr() const;
  // The wall clock's milliseconds across the top (config.clockStamp).
  void drawClockStamp(cv::Mat& image) const;

  const Pose2& car() const { return car_; }
  // The car and the target as of the last step, for other threads (the
  // simulated Marvelmind dashboard reads its beacons' truth here).
  struct Truth {
    Pose2 car, target;
  };
  Truth truthNow() const;
  const Pose2& target() const { return target_; }
  std::vector<TagView> tagViews() const;
  double bearingDeg() const;  // target direction seen from the car, + = left
  double distance() const;    // camera to target tag, m
  FollowSummary summary() const;
  const FollowSceneConfig& config() const { return config_; }

 private:
  FollowScene(FollowSceneConfig config, vision::TagFamily family);

  struct PlacedTag {
    int id;
    cv::Mat pattern;  // the tag image, scaled up, in BGR like the frame
    Pose2 pose;       // the tag faces along pose.theta + π (towards -heading)
  };

  void moveTarget(double seconds);
  void drive(double seconds, const wirc::ChannelOutputs& outputs);
  void writeTruth();
  std::array<cv::Point3d, 4> tagCorners(const Pose2& pose, double halfWidth) const;
  bool project(const cv::Point3d& world, cv::Point2d& pixel) const;
  void drawGround(cv::Mat& image) const;
  void drawTag(cv::Mat& image, const PlacedTag& tag) const;

  FollowSceneConfig config_;
  vision::TagFamily family_;
  double fx_;
  double cx_;
  double cy_;
  std::vector<PlacedTag> tags_;
  Pose2 car_;
  Pose2 target_;
  double speed_ = 0;
  double time_ = 0;
  std::optional<wirc::DeviceClock::time_point> lastAdvance_;
  FILE* truth_ = nullptr;
  mutable std::mutex sharedMutex_;
  std::unique_ptr<void, int (*)(void*)> encoder_;  // TurboJPEG, kept across frames
  // Written on the device's thread under sharedMutex_, read under it elsewhere.
  Truth shared_;
  uint64_t ticks_ = 0;
  double bearingSum_ = 0;
  double distanceErrorSum_ = 0;
  FollowSummary summary_;
  wirc::ChannelOutputs lastOutputs_;
  std::atomic<bool> targetHidden_{false};
  bool driverReady_ = false;
};

Expected<TargetPath, std::string> parseTargetPath(const std::string& name);

}  // namespace wircam::sim
