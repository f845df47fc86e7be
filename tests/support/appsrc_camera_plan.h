// The recorder's plan for a camera whose source is an appsrc (named "src")
// of CIF JPEG at 15 fps, for a camera in a test's or a benchmark's own
// process: it pushes the frames, no device, no socket.
#pragma once

#include "camera/pipeline_plan.h"

namespace wircam::testing {

inline constexpr char kAppSrcCamera[] =
    "appsrc name=src format=time caps=image/jpeg,width=352,height=288,framerate=15/1";

// The appsrc is the source and the tail (nothing branches), the recorder's
// Matroska muxer, no text track.
inline recorder::StreamPlan appSrcCameraPlan() {
  recorder::StreamPlan plan;
  plan.description = kAppSrcCamera;
  plan.device = "bench";
  plan.name = "bench-cam0";
  plan.source = plan.videoTail = "src";
  plan.muxer = recorder::matroskaMuxer();
  plan.muxer.text = false;
  return plan;
}

// With the recorder's text track (its default): the telemetry's tail.
inline void addTextTrack(recorder::StreamPlan& plan) {
  plan.description += " taginject name=teltag";
  plan.telemetryTail = "teltag";
  plan.muxer.text = true;
}

}  // namespace wircam::testing
