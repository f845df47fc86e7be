// The text tracks of every camera writing Matroska, fed from one thread
// shared while used, not from one a camera.
//
// matroskamux (GStreamer 1.22, GstCollectPads) takes a frame only once its
// text track has passed the frame's time, and a line only once a frame
// waits beside it: a line pushed on the frames' own thread would wait for
// a frame that thread is yet to bring. So, as each frame is about to enter
// its muxer (TextOutlet::beforeFrame, on the frame's thread):
// - with no line due, the frame's thread says that the text has nothing
//   up to the frame (a gap, which reaches the muxer as a GAP event and
//   never waits), and the frame goes straight through: no thread wakes;
// - with lines due, it hands them and the gap to the text thread and
//   pushes the frame, which waits in the muxer: each line goes in beside
//   it, and the gap then lets it through. The text thread waits only for
//   a frame already on its way: the handing over is the last thing the
//   frame's thread does before its push.
// Once something of a track is with the text thread, its later buffers
// follow it there, so that a frame's thread never waits behind a line.
#pragma once

#include <gst/gst.h>

#include <condition_variable>
#include <deque>
#include <memory>
#include <mutex>
#include <thread>
#include <vector>

#include "telemetry/text_outlet.h"

namespace wircam::recorder {

class TextFeeder {
 public:
  // The thread, made at the first use and shared while any track holds it.
  static std::shared_ptr<TextFeeder> shared();
  ~TextFeeder();  // once no track is left
  TextFeeder(const TextFeeder&) = delete;
  TextFeeder& operator=(const TextFeeder&) = delete;

  // A track whose first element's sink pad is `input` (a reference is
  // taken): what it is handed goes in there, in order.
  static std::unique_ptr<TextOutlet> outletInto(GstPad* input);

 private:
  class Outlet;
  struct Batch {
    std::vector<GstBuffer*> buffers;
    bool end = false;  // EOS after them
  };

  TextFeeder();
  void post(Outlet& outlet, Batch batch);
  void run();

  std::mutex mutex_;
  std::condition_variable wake_, idle_;
  std::deque<Outlet*> ready_;  // the tracks with batches, in turn
  bool stopping_ = false;
  std::thread thread_;
};

}  // namespace wircam::recorder
