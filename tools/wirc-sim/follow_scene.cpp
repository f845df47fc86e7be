#include "follow_scene.h"

#include <turbojpeg.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <opencv2/imgproc.hpp>

namespace wircam::sim {

namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr int kPatternScale = 16;       // pixels per tag cell before warping
constexpr double kBoardScale = 1.6;     // white board around the tag, × tag size
constexpr double kSettleSeconds = 3.0;  // the summary ignores the start
constexpr double kMaxStep = 0.01;       // s, integration step
constexpr double kSpeedTimeConstant = 0.25;

// Tag corners as (x right, y up) on the printed tag, in the order the AprilTag
// detector reports p[0..3] for an upright tag: bottom-left, bottom-right,
// top-right, top-left (checked by the render test).
constexpr std::array<std::array<double, 2>, 4> kCornerOrder = {
    {{-1, -1}, {1, -1}, {1, 1}, {-1, 1}}};

double wrapAngle(double a) { return std::atan2(std::sin(a), std::cos(a)); }

double pulseOrNeutral(uint16_t pulse) { return pulse == 0 ? wirc::kPulseNeutral : pulse; }

double turn(cv::Point2d a, cv::Point2d b, cv::Point2d c) {
  return (b.x - a.x) * (c.y - a.y) - (b.y - a.y) * (c.x - a.x);
}

// True when the projected corners run the same way round as on the printed
// tag (image y down): the camera sees the tag's face, not its back.
bool facesCamera(const std::array<cv::Point2d, 4>& c) {
  auto printed = [](size_t i) { return cv::Point2d(kCornerOrder[i][0], -kCornerOrder[i][1]); };
  return (turn(c[0], c[1], c[2]) > 0) == (turn(printed(0), printed(1), printed(2)) > 0);
}

}  // namespace

Expected<TargetPath, std::string> parseTargetPath(const std::string& name) {
  if (name == "still") return TargetPath::Still;
  if (name == "line") return TargetPath::Line;
  if (name == "circle") return TargetPath::Circle;
  return unexpected("unknown path '" + name + "' (still, line or circle)");
}

Expected<std::unique_ptr<FollowScene>, std::string> FollowScene::create(FollowSceneConfig config) {
  if (config.width < 16 || config.height < 16 || config.width > 4096 || config.height > 4096)
    return unexpected(std::string("frame size must be 16..4096 pixels each way"));
  if (config.tagIds.empty()) return unexpected(std::string("at least one tag id is needed"));
  if (config.steeringChannel < 1 || config.steeringChannel > 8 || config.throttleChannel < 1 ||
      config.throttleChannel > 8 || config.steeringChannel == config.throttleChannel)
    return unexpected(std::string("steering and throttle channels must be two of 1..8"));
  auto family = vision::TagFamily::create(config.family);
  if (!family) return unexpected(family.error());
  for (int id : config.tagIds) {
    if (id < 0 || id >= family->codeCount())
      return unexpected("tag id " + std::to_string(id) + " is not in " + config.family + " (0.." +
                        std::to_string(family->codeCount() - 1) + ")");
  }
  return std::unique_ptr<FollowScene>(new FollowScene(std::move(config), std::move(*family)));
}

FollowScene::FollowScene(FollowSceneConfig config, vision::TagFamily family)
    : config_(std::move(config)),
      family_(std::move(family)),
      encoder_(tjInitCompress(), tjDestroy) {
  fx_ = config_.width / 2.0 / std::tan(config_.horizontalFovDeg * kPi / 360.0);
  cx_ = config_.width / 2.0 - 0.5;
  cy_ = config_.height / 2.0 - 0.5;
  target_ = {config_.startDistance, 0, 0};
  for (size_t i = 0; i < config_.tagIds.size(); ++i) {
    PlacedTag tag;
    tag.id = config_.tagIds[i];
    int cells = family_.totalWidth();
    auto cellValues = family_.image(tag.id);
    cv::Mat small(cells, cells, CV_8UC1, cellValues.data());
    cv::Mat scaled;
    cv::resize(small, scaled, {}, kPatternScale, kPatternScale, cv::INTER_NEAREST);
    cv::cvtColor(scaled, tag.pattern, cv::COLOR_GRAY2BGR);
    if (i > 0) {
      // Landmarks on a ring around the start, facing it.
      double angle =
          2 * kPi * static_cast<double>(i - 1) / static_cast<double>(config_.tagIds.size() - 1) +
          kPi / 4;
      tag.pose = {6 * std::cos(angle), 6 * std::sin(angle), angle};
    }
    tags_.push_back(std::move(tag));
  }
  tags_[0].pose = target_;
  shared_ = {car_, target_};
}

FollowScene::~FollowScene() {
  if (truth_) std::fclose(truth_);
}

std::optional<std::string> FollowScene::writeTruthTo(const std::string& path) {
  FILE* file = std::fopen(path.c_str(), "w");
  if (!file) return "cannot write the truth file '" + path + "': " + std::strerror(errno);
  if (truth_) std::fclose(truth_);
  truth_ = file;
  return std::nullopt;
}

void FollowScene::advance(wirc::DeviceClock::time_point now, const wirc::ChannelOutputs& outputs) {
  double seconds = lastAdvance_ ? std::chrono::duration<double>(now - *lastAdvance_).count() : 0;
  lastAdvance_ = now;
  // On the device the world waits for its driver: nothing moves before the
  // first PCD, so a slow start of the controlling pipeline is not held
  // against it. (The static scene has no driver.)
  if (!outputs.failsafe) driverReady_ = true;
  if (!driverReady_ && !config_.carFixed) seconds = 0;
  step(seconds, outputs);
}

void FollowScene::step(double seconds, const wirc::ChannelOutputs& outputs) {
  lastOutputs_ = outputs;
  for (double left = seconds; left > 0; left -= kMaxStep) {
    double dt = std::min(left, kMaxStep);
    moveTarget(dt);
    if (!config_.carFixed) drive(dt, outputs);
    time_ += dt;
  }
  double bearing = std::abs(bearingDeg());
  double error = std::abs(distance() - config_.followDistance);
  // The truth and the summary are read from other threads (summary(),
  // truthNow()): written under the lock they read them under.
  {
    std::lock_guard lock(sharedMutex_);
    ++ticks_;
    shared_ = {car_, target_};
    if (time_ >= kSettleSeconds) {
      ++summary_.measuredTicks;
      bearingSum_ += bearing;
      distanceErrorSum_ += error;
      summary_.maxBearingDeg = std::max(summary_.maxBearingDeg, bearing);
      summary_.maxDistanceError = std::max(summary_.maxDistanceError, error);
    }
  }
  writeTruth();
}

FollowScene::Truth FollowScene::truthNow() const {
  std::lock_guard lock(sharedMutex_);
  return shared_;
}

void FollowScene::moveTarget(double dt) {
  double distance = config_.targetSpeed * dt;
  switch (config_.path) {
    case TargetPath::Still:
      return;
    case TargetPath::Line:
      break;
    case TargetPath::Circle:
      target_.theta = wrapAngle(target_.theta + distance / config_.circleRadius);
      break;
  }
  target_.x += distance * std::cos(target_.theta);
  target_.y += distance * std::sin(target_.theta);
  tags_[0].pose = target_;
}

void FollowScene::drive(double dt, const wirc::ChannelOutputs& outputs) {
  double steer = pulseOrNeutral(outputs.pulses[config_.steeringChannel - 1]);
  double throttle = pulseOrNeutral(outputs.pulses[config_.throttleChannel - 1]);
  double delta = std::clamp((steer - wirc::kPulseNeutral) / 500.0, -1.0, 1.0) * config_.maxSteerRad;
  double offset = throttle - wirc::kPulseNeutral;
  double drive = 0;
  if (std::abs(offset) > config_.throttleDeadband)
    drive = (offset - std::copysign(config_.throttleDeadband, offset)) /
            (500.0 - config_.throttleDeadband);
  double wanted = std::clamp(drive, -1.0, 1.0) * config_.maxSpeed;
  speed_ += (wanted - speed_) * std::min(1.0, dt / kSpeedTimeConstant);
  car_.x += speed_ * std::cos(car_.theta) * dt;
  car_.y += speed_ * std::sin(car_.theta) * dt;
  car_.theta = wrapAngle(car_.theta + speed_ / config_.wheelbase * std::tan(delta) * dt);
}

double FollowScene::bearingDeg() const {
  double dx = target_.x - car_.x, dy = target_.y - car_.y;
  return wrapAngle(std::atan2(dy, dx) - car_.theta) * 180.0 / kPi;
}

double FollowScene::distance() const { return std::hypot(target_.x - car_.x, target_.y - car_.y); }

FollowSummary FollowScene::summary() const {
  std::lock_guard lock(sharedMutex_);
  FollowSummary s = summary_;
  s.ticks = ticks_;
  if (s.measuredTicks > 0) {
    s.meanBearingDeg = bearingSum_ / static_cast<double>(s.measuredTicks);
    s.meanDistanceError = distanceErrorSum_ / static_cast<double>(s.measuredTicks);
  }
  return s;
}

std::array<cv::Point3d, 4> FollowScene::tagCorners(const Pose2& pose, double halfWidth) const {
  // The tag faces back along -heading; seen from behind, its image x runs to
  // the viewer's right (-lateral) and its image y runs down.
  cv::Point3d center(pose.x, pose.y, config_.cameraHeight);
  cv::Point3d right(std::sin(pose.theta), -std::cos(pose.theta), 0);
  cv::Point3d down(0, 0, -1);
  std::array<cv::Point3d, 4> corners;
  for (size_t i = 0; i < 4; ++i)
    corners[i] = center + right * (kCornerOrder[i][0] * halfWidth) +
                 down * (-kCornerOrder[i][1] * halfWidth);
  return corners;
}

bool FollowScene::project(const cv::Point3d& world, cv::Point2d& pixel) const {
  cv::Point3d d(world.x - car_.x, world.y - car_.y, world.z - config_.cameraHeight);
  double forward = d.x * std::cos(car_.theta) + d.y * std::sin(car_.theta);
  double left = -d.x * std::sin(car_.theta) + d.y * std::cos(car_.theta);
  if (forward < 0.05) return false;
  pixel = {fx_ * -left / forward + cx_, fx_ * -d.z / forward + cy_};
  return true;
}

std::vector<TagView> FollowScene::tagViews() const {
  std::vector<TagView> views;
  double half = config_.tagSize / 2;
  for (const auto& tag : tags_) {
    TagView view;
    view.id = tag.id;
    view.visible = true;
    auto corners = tagCorners(tag.pose, half);
    for (size_t i = 0; i < 4; ++i) {
      bool front = project(corners[i], view.corners[i]);
      bool inside = view.corners[i].x >= 0 && view.corners[i].y >= 0 &&
                    view.corners[i].x <= config_.width - 1 &&
                    view.corners[i].y <= config_.height - 1;
      view.visible = view.visible && front && inside;
    }
    view.visible =
        view.visible && facesCamera(view.corners) && (&tag != &tags_[0] || !targetHidden_);
    views.push_back(view);
  }
  return views;
}

void FollowScene::drawGround(cv::Mat& image) const {
  const cv::Vec3b skyTop(235, 200, 150), skyHorizon(250, 235, 215);  // BGR
  const cv::Vec3b light(140, 160, 150), dark(95, 110, 100);
  double cosT = std::cos(car_.theta), sinT = std::sin(car_.theta);
  for (int v = 0; v < image.rows; ++v) {
    auto* row = image.ptr<cv::Vec3b>(v);
    double down = (v - cy_) / fx_;
    if (down <= 0.002) {
      double k = std::clamp(v / cy_, 0.0, 1.0);
      cv::Vec3b sky;
      for (int ch = 0; ch < 3; ++ch)
        sky[ch] = static_cast<uint8_t>(skyTop[ch] * (1 - k) + skyHorizon[ch] * k);
      std::fill(row, row + image.cols, sky);
      continue;
    }
    double t = config_.cameraHeight / down;  // ray length to the ground, per unit forward
    double fog = std::min(1.0, t / 40.0);
    // Ground point = car + t·(forward + dx·right), linear in the column.
    double baseX = car_.x + t * cosT, baseY = car_.y + t * sinT;
    double stepX = t * sinT / fx_, stepY = -t * cosT / fx_;
    for (int u = 0; u < image.cols; ++u) {
      double dx = u - cx_;
      double gx = baseX + stepX * dx, gy = baseY + stepY * dx;
      bool check =
          (static_cast<long>(std::floor(gx * 2)) + static_cast<long>(std::floor(gy * 2))) & 1;
      const cv::Vec3b& tile = check ? light : dark;
      for (int ch = 0; ch < 3; ++ch)
        row[u][ch] = static_cast<uint8_t>(tile[ch] * (1 - fog) + skyHorizon[ch] * fog);
    }
  }
}

void FollowScene::drawTag(cv::Mat& image, const PlacedTag& tag) const {
  double half = config_.tagSize / 2;
  double boardHalf = half * kBoardScale * family_.totalWidth() / family_.borderWidth();
  std::array<cv::Point2d, 4> board, border;
  auto boardCorners = tagCorners(tag.pose, boardHalf);
  auto borderCorners = tagCorners(tag.pose, half);
  for (size_t i = 0; i < 4; ++i) {
    if (!project(boardCorners[i], board[i]) || !project(borderCorners[i], border[i])) return;
  }
  bool front = facesCamera(border);
  std::vector<cv::Point> boardPolygon;
  for (const auto& p : board) boardPolygon.emplace_back(cvRound(p.x), cvRound(p.y));
  cv::fillConvexPoly(image, boardPolygon,
                     front ? cv::Scalar(245, 245, 245) : cv::Scalar(90, 90, 90), cv::LINE_AA);
  if (!front) return;

  // Map the tag's border square (in pattern pixels) onto its projection.
  double first = (family_.totalWidth() - family_.borderWidth()) / 2.0 * kPatternScale - 0.5;
  double last = first + family_.borderWidth() * kPatternScale;
  std::array<cv::Point2f, 4> from, to;
  for (size_t i = 0; i < 4; ++i) {
    from[i] = {static_cast<float>(kCornerOrder[i][0] < 0 ? first : last),
               static_cast<float>(kCornerOrder[i][1] > 0 ? first : last)};
    to[i] = border[i];
  }
  cv::Mat homography = cv::getPerspectiveTransform(from.data(), to.data());
  // Warp into the bounding box only: a full-frame warp costs per pixel.
  cv::Rect box = cv::boundingRect(boardPolygon) & cv::Rect(0, 0, image.cols, image.rows);
  if (box.empty()) return;
  cv::Mat shift = (cv::Mat_<double>(3, 3) << 1, 0, -box.x, 0, 1, -box.y, 0, 0, 1);
  cv::Mat roi = image(box);
  cv::warpPerspective(tag.pattern, roi, shift * homography, roi.size(), cv::INTER_LINEAR,
                      cv::BORDER_TRANSPARENT);
}

cv::Mat FollowScene::renderBgr() const {
  cv::Mat image(config_.height, config_.width, CV_8UC3);
  drawGround(image);
  // Far tags first, so nearer ones cover them.
  std::vector<const PlacedTag*> order;
  for (const auto& tag : tags_)
    if (&tag != &tags_[0] || !targetHidden_) order.push_back(&tag);
  auto range = [&](const PlacedTag* t) {
    return std::hypot(t->pose.x - car_.x, t->pose.y - car_.y);
  };
  std::sort(order.begin(), order.end(), [&](auto* a, auto* b) { return range(a) > range(b); });
  for (const auto* tag : order) drawTag(image, *tag);
  return image;
}

void FollowScene::drawClockStamp(cv::Mat& image) const {
  auto now = std::chrono::duration_cast<std::chrono::milliseconds>(
      std::chrono::system_clock::now().time_since_epoch());
  auto stamp = static_cast<uint32_t>(now.count());
  // Blocks big enough to survive JPEG and a video encoder at low rates.
  int width = image.cols / kStampBits, height = std::max(16, image.rows / 16);
  for (int bit = 0; bit < kStampBits; ++bit) {
    bool one = (stamp >> (kStampBits - 1 - bit)) & 1;
    cv::rectangle(image, cv::Rect(bit * width, 0, width, height),
                  one ? cv::Scalar(255, 255, 255) : cv::Scalar(0, 0, 0), cv::FILLED);
  }
}

std::vector<uint8_t> FollowScene::renderJpeg(int camera) {
  // Every camera looks forward: the simulated vehicle carries its cameras
  // side by side, which is what the multi-camera tests need.
  (void)camera;
  cv::Mat image = renderBgr();
  if (config_.clockStamp) drawClockStamp(image);
  unsigned char* jpeg = nullptr;
  unsigned long size = 0;
  if (tjCompress2(encoder_.get(), image.data, image.cols, static_cast<int>(image.step), image.rows,
                  TJPF_BGR, &jpeg, &size, TJSAMP_420, config_.jpegQuality, TJFLAG_FASTDCT) != 0)
    return {};
  std::vector<uint8_t> bytes(jpeg, jpeg + size);
  tjFree(jpeg);
  return bytes;
}

void FollowScene::writeTruth() {
  if (!truth_) return;
  // unix_ms: wall-clock time, to match the truth with recordings' utc.
  auto unixMs = std::chrono::duration_cast<std::chrono::milliseconds>(
                    std::chrono::system_clock::now().time_since_epoch())
                    .count();
  std::fprintf(
      truth_,
      "{\"tick\":%llu,\"unix_ms\":%lld,\"t\":%.4f,\"car\":{\"x\":%.4f,\"y\":%.4f,\"theta\":%.5f},"
      "\"target\":{\"x\":%.4f,\"y\":%.4f,\"theta\":%.5f},\"bearing_deg\":%.3f,"
      "\"distance_m\":%.4f,\"distance_error_m\":%.4f,\"failsafe\":%s,"
      "\"steering_us\":%u,\"throttle_us\":%u,\"tags\":[",
      static_cast<unsigned long long>(ticks_), static_cast<long long>(unixMs), time_, car_.x,
      car_.y, car_.theta, target_.x, target_.y, target_.theta, bearingDeg(), distance(),
      distance() - config_.followDistance, lastOutputs_.failsafe ? "true" : "false",
      lastOutputs_.pulses[config_.steeringChannel - 1],
      lastOutputs_.pulses[config_.throttleChannel - 1]);
  auto views = tagViews();
  for (size_t i = 0; i < views.size(); ++i) {
    const auto& c = views[i].corners;
    std::fprintf(truth_,
                 "%s{\"id\":%d,\"visible\":%s,\"corners\":[[%.2f,%.2f],[%.2f,%.2f],[%.2f,%.2f],"
                 "[%.2f,%.2f]]}",
                 i ? "," : "", views[i].id, views[i].visible ? "true" : "false", c[0].x, c[0].y,
                 c[1].x, c[1].y, c[2].x, c[2].y, c[3].x, c[3].y);
  }
  std::fputs("]}\n", truth_);
}

}  // namespace wircam::sim
