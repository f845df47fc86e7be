// The recorder's options made into each camera's pipeline plan: the app
// plans, each camera receives only its own StreamPlan.
#pragma once

#include <optional>
#include <string>

#include "app/recorder_options.h"
#include "camera/pipeline_plan.h"

namespace wircam::recorder {

// Each stream is a pipeline of its own, so that a camera that never sends a
// frame, errors or stalls holds no other camera's preroll, EOS or stop.
// Per stream: wircsrc → [marvelmindpositions →] [tee →] [decode → x264enc →]
// (the file), the telemetry's text (the same file, unless
// --telemetry-track off; for MP4 from an appsrc) and, when asked for, a
// leaky branch off the tee to AprilTag detection (→ wirccontrol) and one
// to an appsink for the live view and RTSP. The files themselves (a muxer
// and a sink each) are not in the description: the recorder's
// SegmentWriter puts each in at its first frame and takes it out when it
// is finished. A slow disk holds up neither the source nor the live and
// detection branches (hence following), nor another camera: the files'
// bytes are written by their filesystem's thread, each camera's bounded
// (camera/disk_writer.h). A camera is one thread, its source's: the
// muxer, the text track's lines and the hand-over to the disk are on it.
PipelinePlan planPipeline(const RecorderOptions& options);

// Two streams of one name (devices whose names differ only in what a file
// name cannot hold, "a b" and "a_b"; a camera listed twice) would write
// each other's files: why the plan cannot be recorded, if so.
std::optional<std::string> sameNamedStreams(const PipelinePlan& plan);

// One camera of one device (as addressed) under two device names: the
// device streams it to one of them at a time, and each would take the
// stream from the other. Why the options cannot be recorded, if so.
std::optional<std::string> cameraRecordedTwice(const RecorderOptions& options);

}  // namespace wircam::recorder
