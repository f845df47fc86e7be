// ROI tracking: once tags are known, look for them only around where they
// were (a window predicted from their last motion, searched at full
// resolution), and search the whole frame only every `fullFrameInterval`
// frames or when a tracked tag is not found. Much less image to scan per
// frame; new tags are found at the next full search.
#pragma once

#include <optional>
#include <vector>

#include "tag_detector.h"

namespace wircam::vision {

struct TrackerOptions {
  int fullFrameInterval = 10;  // frames between full-frame searches
  double margin = 1.0;         // window padding around a tag, in tag sizes
  int minWindow = 48;          // pixels: smaller windows are grown to this
};

struct TrackerStats {
  uint64_t frames = 0;
  uint64_t fullSearches = 0;
  uint64_t windowSearches = 0;
  uint64_t fallbacks = 0;  // a tracked tag was lost, the frame was searched whole
};

class TagTracker {
 public:
  static Expected<TagTracker, std::string> create(const DetectorOptions& options,
                                                  TrackerOptions tracking = {});

  std::vector<TagDetection> detect(const GrayView& image);
  const TrackerStats& stats() const { return stats_; }

 private:
  TagTracker(TagDetector full, std::optional<TagDetector> window, TrackerOptions tracking);
  std::vector<TagDetection> searchWindows(const GrayView& image);

  TagDetector full_;
  // No decimation (windows are small); only with tracking on
  // (fullFrameInterval > 1), or every frame is a full search anyway.
  std::optional<TagDetector> window_;
  TrackerOptions tracking_;
  std::vector<TagDetection> previous_;
  std::vector<TagDetection> beforePrevious_;
  int sinceFullSearch_ = 0;
  TrackerStats stats_;
};

}  // namespace wircam::vision
