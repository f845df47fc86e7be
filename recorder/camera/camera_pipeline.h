// One run of a camera's pipeline, from its start to its teardown: the
// GstPipeline built from the camera's plan, and what follows its frames
// into files (the segment planner and writer, the telemetry track and
// router). A camera restarted after a fault gets a new one; its files go on
// under new names, each starting at its first frame.
#pragma once

#include <gst/gst.h>

#include <atomic>
#include <memory>
#include <optional>
#include <string>

#include "camera/disk_writer.h"
#include "camera/frame_tap.h"
#include "camera/pipeline_plan.h"
#include "camera/segment_writer.h"
#include "common/expected.h"
#include "record/segment_planner.h"
#include "telemetry/telemetry_router.h"
#include "telemetry/telemetry_track.h"
#include "telemetry/text_outlet.h"

namespace wircam::recorder {

struct CameraFiles {
  std::string folder;
  std::string extension;  // ".mkv", ".mp4"
  SegmentLimits limits;
  bool transcoded = false;  // frames pass an encoder that makes key frames on request
  bool operator==(const CameraFiles&) const = default;
};

class CameraPipeline {
 public:
  // `frames` (the camera's live tap, or null) is attached to its appsink;
  // `encoded` (or null) to its encoder's output, when it has one.
  static Expected<std::unique_ptr<CameraPipeline>, std::string> build(const StreamPlan& plan,
                                                                      const CameraFiles& files,
                                                                      FrameTap* frames,
                                                                      FrameTap* encoded);
  ~CameraPipeline();  // torn down (NULL) and released
  CameraPipeline(const CameraPipeline&) = delete;
  CameraPipeline& operator=(const CameraPipeline&) = delete;

  GstElement* pipeline() const { return pipeline_; }
  // An element of this pipeline by name (borrowed), or null.
  GstElement* element(const std::string& name) const;
  // Where the files' text track goes (null: they have none).
  std::unique_ptr<TextOutlet> textOutlet(const StreamPlan& plan) const;
  SegmentPlanner& planner() { return *planner_; }
  TelemetryTrack& track() { return *track_; }
  TelemetryRouter& telemetry() { return *telemetry_; }
  SegmentWriter& writer() { return *writer_; }
  // The running time now, or GST_CLOCK_TIME_NONE before PLAYING.
  GstClockTime runningTime() const;
  bool hasFrames() const { return planner_->current().has_value(); }
  // Frames that reached the files' planner so far (any thread).
  uint64_t framesPlanned() const { return framesPlanned_.load(); }
  // The frames dropped for want of room (their disk behind), this run.
  uint64_t framesDropped() const { return disk_.budget ? disk_.budget->framesDropped() : 0; }
  // The frames that came for the files: the camera's health counts these,
  // not the ones written (a slow disk is not a camera without video).
  uint64_t framesArrived() const {
    return disk_.budget ? disk_.budget->framesArrived() : framesPlanned();
  }

 private:
  CameraPipeline() = default;

  GstElement* pipeline_ = nullptr;
  FrameTap* frames_ = nullptr;
  FrameTap* encoded_ = nullptr;
  CameraDisk disk_;
  std::unique_ptr<SegmentPlanner> planner_;
  std::unique_ptr<TelemetryTrack> track_;
  std::unique_ptr<TelemetryRouter> telemetry_;
  std::unique_ptr<SegmentWriter> writer_;
  std::atomic<uint64_t> framesPlanned_{0};
};

}  // namespace wircam::recorder
