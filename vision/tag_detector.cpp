#include "tag_detector.h"

#include <apriltag/apriltag.h>
#include <apriltag/apriltag_pose.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>

namespace wircam::vision {

Expected<TagDetector, std::string> TagDetector::create(const DetectorOptions& options) {
  if (options.quadDecimate < 1.0f) return unexpected(std::string("quad-decimate must be >= 1"));
  if (options.threads < 1) return unexpected(std::string("threads must be >= 1"));
  // apriltag.h warns that 3 "consumes prohibitively large amounts of
  // memory": building such a detector took 2.4 GB and 1.8 s here.
  if (options.maxHamming < 0 || options.maxHamming > kMaxHamming)
    return unexpected("max-hamming must be 0.." + std::to_string(kMaxHamming) +
                      " (3 needs gigabytes for the decoding table)");
  if (options.pose &&
      (options.pose->tagSize <= 0 || options.pose->fx <= 0 || options.pose->fy <= 0))
    return unexpected(std::string("pose needs tag-size, fx and fy above 0"));
  auto family = TagFamily::create(options.family);
  if (!family) return unexpected(family.error());
  return TagDetector(options, std::move(*family));
}

TagDetector::TagDetector(DetectorOptions options, TagFamily family)
    : options_(std::move(options)),
      family_(std::move(family)),
      detector_(apriltag_detector_create(), apriltag_detector_destroy) {
  apriltag_detector_add_family_bits(detector_.get(), family_.get(), options_.maxHamming);
  detector_->quad_decimate = options_.quadDecimate;
  detector_->quad_sigma = options_.quadSigma;
  detector_->nthreads = options_.threads;
  detector_->refine_edges = options_.refineEdges;
  detector_->decode_sharpening = options_.decodeSharpening;
}

std::vector<TagDetection> TagDetector::detect(const GrayView& image, Point2 origin) {
  // The library's thresholding crashes on an image (after decimation) a
  // few pixels high or wide (a 100x2 frame did, a stranger's trial; so
  // could a search window clipped at the frame's edge), and no tag fits
  // in less than 8 pixels: nothing to find.
  constexpr int kSmallestTag = 8;
  float decimate = std::max(1.0f, detector_->quad_decimate);
  if (image.width / decimate < kSmallestTag || image.height / decimate < kSmallestTag) return {};
  // The library takes a mutable buffer but only reads it.
  image_u8_t view{image.width, image.height, image.stride, const_cast<uint8_t*>(image.data)};
  std::unique_ptr<zarray_t, void (*)(zarray_t*)> found(
      apriltag_detector_detect(detector_.get(), &view), apriltag_detections_destroy);
  std::vector<TagDetection> detections;
  for (int i = 0; i < zarray_size(found.get()); ++i) {
    apriltag_detection_t* d = nullptr;
    zarray_get(found.get(), i, &d);
    if (d->hamming > options_.maxHamming || d->decision_margin < options_.minMargin) continue;
    if (origin.x != 0 || origin.y != 0) {
      // Into the whole frame's pixels: shift the points, and the homography
      // by the same translation (T·H), before anything (pose) reads them.
      for (auto& p : d->p) {
        p[0] += origin.x;
        p[1] += origin.y;
      }
      d->c[0] += origin.x;
      d->c[1] += origin.y;
      double* h = d->H->data;
      for (int column = 0; column < 3; ++column) {
        h[column] += origin.x * h[6 + column];
        h[3 + column] += origin.y * h[6 + column];
      }
    }
    TagDetection detection;
    detection.id = d->id;
    detection.family = family_.name();
    detection.hamming = d->hamming;
    detection.margin = d->decision_margin;
    detection.center = {d->c[0], d->c[1]};
    for (int c = 0; c < 4; ++c) detection.corners[c] = {d->p[c][0], d->p[c][1]};
    for (int k = 0; k < 9; ++k) detection.homography[k] = d->H->data[k];
    if (const auto& camera = options_.pose) {
      apriltag_detection_info_t info{d,          camera->tagSize, camera->fx,
                                     camera->fy, camera->cx,      camera->cy};
      apriltag_pose_t pose{};
      estimate_tag_pose(&info, &pose);
      // Yaw from the rotation's third column (the tag's normal) seen from above.
      detection.pose = TagPose{MATD_EL(pose.t, 0, 0), MATD_EL(pose.t, 1, 0), MATD_EL(pose.t, 2, 0),
                               std::atan2(MATD_EL(pose.R, 0, 2), MATD_EL(pose.R, 2, 2))};
      // Debian's libapriltag does not export matd_destroy; a matd_t is one
      // malloc'd block (common/matd.c), so free it as that would.
      std::free(pose.R);
      std::free(pose.t);
    }
    detections.push_back(std::move(detection));
  }
  return detections;
}

}  // namespace wircam::vision
