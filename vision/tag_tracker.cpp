#include "tag_tracker.h"

#include <algorithm>
#include <cmath>

namespace wircam::vision {

namespace {

struct Window {
  int x0, y0, x1, y1;  // half-open
};

double edgeLength(const TagDetection& d) {
  return std::hypot(d.corners[1].x - d.corners[0].x, d.corners[1].y - d.corners[0].y);
}

// Where the tag should be now: its last box moved by its last motion.
Window predict(const TagDetection& last, const TagDetection* before, const TrackerOptions& o,
               int width, int height) {
  double dx = before ? last.center.x - before->center.x : 0;
  double dy = before ? last.center.y - before->center.y : 0;
  double minX = 1e9, minY = 1e9, maxX = -1e9, maxY = -1e9;
  for (const auto& c : last.corners) {
    minX = std::min(minX, c.x + dx);
    maxX = std::max(maxX, c.x + dx);
    minY = std::min(minY, c.y + dy);
    maxY = std::max(maxY, c.y + dy);
  }
  double pad = std::max(o.margin * edgeLength(last), (o.minWindow - (maxX - minX)) / 2);
  double padY = std::max(o.margin * edgeLength(last), (o.minWindow - (maxY - minY)) / 2);
  return {std::clamp(static_cast<int>(minX - pad), 0, width),
          std::clamp(static_cast<int>(minY - padY), 0, height),
          std::clamp(static_cast<int>(std::ceil(maxX + pad)), 0, width),
          std::clamp(static_cast<int>(std::ceil(maxY + padY)), 0, height)};
}

}  // namespace

Expected<TagTracker, std::string> TagTracker::create(const DetectorOptions& options,
                                                     TrackerOptions tracking) {
  if (tracking.fullFrameInterval < 1)
    return unexpected(std::string("the full-frame interval must be >= 1"));
  auto full = TagDetector::create(options);
  if (!full) return unexpected(full.error());
  std::optional<TagDetector> window;
  if (tracking.fullFrameInterval > 1) {
    DetectorOptions windowOptions = options;
    windowOptions.quadDecimate = 1;
    auto created = TagDetector::create(windowOptions);
    if (!created) return unexpected(created.error());
    window.emplace(std::move(*created));
  }
  return TagTracker(std::move(*full), std::move(window), tracking);
}

TagTracker::TagTracker(TagDetector full, std::optional<TagDetector> window, TrackerOptions tracking)
    : full_(std::move(full)), window_(std::move(window)), tracking_(tracking) {}

std::vector<TagDetection> TagTracker::searchWindows(const GrayView& image) {
  std::vector<TagDetection> found;
  for (const auto& last : previous_) {
    const TagDetection* before = nullptr;
    for (const auto& b : beforePrevious_)
      if (b.id == last.id) before = &b;
    Window w = predict(last, before, tracking_, image.width, image.height);
    if (w.x1 - w.x0 < 8 || w.y1 - w.y0 < 8) return {};
    GrayView crop{image.data + static_cast<ptrdiff_t>(w.y0) * image.stride + w.x0, w.x1 - w.x0,
                  w.y1 - w.y0, image.stride};
    bool seen = false;
    for (auto& d : window_->detect(crop, {static_cast<double>(w.x0), static_cast<double>(w.y0)})) {
      bool duplicate = std::any_of(found.begin(), found.end(),
                                   [&](const TagDetection& f) { return f.id == d.id; });
      seen = seen || d.id == last.id;
      if (!duplicate) found.push_back(std::move(d));
    }
    if (!seen) return {};  // lost: the caller searches the whole frame
  }
  return found;
}

std::vector<TagDetection> TagTracker::detect(const GrayView& image) {
  ++stats_.frames;
  std::vector<TagDetection> found;
  bool full = !window_ || previous_.empty() || ++sinceFullSearch_ >= tracking_.fullFrameInterval;
  if (!full) {
    ++stats_.windowSearches;
    found = searchWindows(image);
    if (found.empty()) {
      ++stats_.fallbacks;
      full = true;
    }
  }
  if (full) {
    ++stats_.fullSearches;
    sinceFullSearch_ = 0;
    found = full_.detect(image);
  }
  beforePrevious_ = std::move(previous_);
  previous_ = found;
  return found;
}

}  // namespace wircam::vision
