// Where a file's text track goes: its buffers, in order, into the muxer's
// text input. Two ways in, after what the muxer does with a line:
// - matroskamux (GStreamer 1.22, GstCollectPads) takes a line only once a
//   frame waits beside it, so a line's push waits for a frame: the lines
//   go from the one text thread the recorder's cameras share, each as a
//   frame is about to enter its muxer (text_feeder.h);
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
  // the frame's thread, which must not wait for the muxer: the frame it is
  // about to push is what the lines wait for.
  virtual void beforeFrame(std::vector<GstBuffer*> lines, GstBuffer* gap) = 0;
  // The track's last buffers (owned), then its end. On any thread.
  virtual void end(std::vector<GstBuffer*> buffers) = 0;
  // Every buffer handed over has gone on to the muxer (where the last line
  // may still wait for a frame, or for the frames' end).
  virtual bool allSent() const = 0;
};

// Pushes into `appsrc` (borrowed), whose thread takes them to the muxer.
std::unique_ptr<TextOutlet> appSrcOutlet(GstElement* appsrc);

}  // namespace wircam::recorder
