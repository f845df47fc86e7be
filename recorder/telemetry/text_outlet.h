// Where a file's text track goes: its buffers, in order, into the muxer's
// text input. Two ways in, after what the muxer does with a line:
// - matroskamux (GStreamer 1.22, GstCollectPads) would take a line only
//   once a frame waits beside it; the file gives each line its turn in
//   the muxer instead (telemetry/collect_pads_turns.h), so the lines go in on
//   the frames' own thread, just before the frame they are due at
//   (frameThreadOutlet below): no thread of the text's own;
// - mp4mux (an aggregator) takes a line without waiting; its text has a
//   thread of its own anyway, an appsrc's (appSrcOutlet below).
#pragma once

#include <gst/gst.h>

#include <memory>
#include <vector>

namespace wircam::recorder {

class TextOutlet {
 public:
  virtual ~TextOutlet() = default;
  // What is due as a frame enters its file: its lines (may be none), then
  // `gap`, which says the text has nothing more up to the frame; owned. On
  // the frame's thread, just before its push.
  virtual void beforeFrame(std::vector<GstBuffer*> lines, GstBuffer* gap) = 0;
  // The track's last buffers (owned), then its end. On any thread.
  virtual void end(std::vector<GstBuffer*> buffers) = 0;
  // The frames end (on their thread, before their end reaches the files):
  // what end() was handed goes in now if it has not yet.
  virtual void framesEnd() {}
  // Every buffer handed over has gone on to the muxer.
  virtual bool allSent() const = 0;
};

// Pushes into `appsrc` (borrowed), whose thread takes them to the muxer.
std::unique_ptr<TextOutlet> appSrcOutlet(GstElement* appsrc);

// Pushes into `input` (a reference is taken), the sink pad of the track's
// first element, on the frames' thread: what end() is handed goes in with
// the next frame's lines, or at the frames' end.
std::unique_ptr<TextOutlet> frameThreadOutlet(GstPad* input);

}  // namespace wircam::recorder
