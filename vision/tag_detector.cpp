#include "tag_detector.h"

#include <apriltag/apriltag.h>

namespace wircam::vision {

Expected<TagDetector, std::string> TagDetector::create(const DetectorOptions& options) {
  if (options.quadDecimate < 1.0f) return unexpected(std::string("quad-decimate must be >= 1"));
  if (options.threads < 1) return unexpected(std::string("threads must be >= 1"));
  if (options.maxHamming < 0 || options.maxHamming > 3)
    return unexpected(std::string("max-hamming must be 0..3"));
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

std::vector<TagDetection> TagDetector::detect(const GrayView& image) {
  // The library takes a mutable buffer but only reads it.
  image_u8_t view{image.width, image.height, image.stride, const_cast<uint8_t*>(image.data)};
  std::unique_ptr<zarray_t, void (*)(zarray_t*)> found(
      apriltag_detector_detect(detector_.get(), &view), apriltag_detections_destroy);
  std::vector<TagDetection> detections;
  for (int i = 0; i < zarray_size(found.get()); ++i) {
    apriltag_detection_t* d = nullptr;
    zarray_get(found.get(), i, &d);
    if (d->hamming > options_.maxHamming || d->decision_margin < options_.minMargin) continue;
    TagDetection detection;
    detection.id = d->id;
    detection.family = family_.name();
    detection.hamming = d->hamming;
    detection.margin = d->decision_margin;
    detection.center = {d->c[0], d->c[1]};
    for (int c = 0; c < 4; ++c) detection.corners[c] = {d->p[c][0], d->p[c][1]};
    for (int k = 0; k < 9; ++k) detection.homography[k] = d->H->data[k];
    detections.push_back(std::move(detection));
  }
  return detections;
}

}  // namespace wircam::vision
