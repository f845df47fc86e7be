#include "camera/pipeline_plan.h"

namespace wircam::recorder {

// Crash safety: Matroska clusters and MP4 fragments of at most 0.5 s (the
// muxers write a cluster or fragment whole), so a killed recorder leaves
// the open segment playable up to about its last second. The text track's
// gaps (TelemetryTrack::heartbeat) reach matroskamux as GAP events, for
// which it writes nothing, not even to the duration; mp4mux (an
// aggregator, GStreamer 1.22) stalls on GAP events, and gets empty buffers
// instead, as it did inside splitmuxsink.
//
// A Matroska cue (the index a player seeks by) for the first key frame of
// each half second, as clusters are cut, not for every one: every JPEG
// frame is a key frame, and matroskamux holds each file's cues in memory
// until its end (24 bytes a frame: 5.5 MB for 256 cameras' minute at
// 15 fps). Seeks stay exact: the demuxer starts at the cue before and the
// playback's seeks are accurate.
MuxerSpec matroskaMuxer() {
  return {
      .factory = "matroskamux",
      .properties = {{"max-cluster-duration", "500000000"}, {"min-index-interval", "500000000"}},
      .textGapEvents = true};
}

MuxerSpec mp4Muxer() {
  return {
      .factory = "mp4mux", .properties = {{"fragment-duration", "500"}}, .textGapEvents = false};
}

std::string PipelinePlan::description() const {
  std::string all;
  for (const auto& stream : streams) all += stream.description;
  return all;
}

}  // namespace wircam::recorder
