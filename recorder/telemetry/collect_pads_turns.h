// One thread feeding both inputs of a muxer driven by GstCollectPads
// (matroskamux in GStreamer 1.22): the camera's frames and its text lines,
// both from the source's thread, with no thread of the text's own.
//
// GstCollectPads hands on a buffer only once every input either holds one
// too or is "not waited for": an input is waited for unless its position
// (its newest buffer's time, or a GAP event's end) is past the earliest
// buffer held. A frame's input is always waited for again once its frame
// has gone on, so a line pushed alone would wait for the next frame, which
// the same thread was to bring. Before a line, the video input says it has
// nothing before the line (a GAP event up to just past it) and is set not
// to be waited for, so the line goes on at once. After the lines the video
// input is waited for again, and the text input, which has just been (its
// line was the earliest), is not: the text's gap that follows says it has
// nothing up to the next frame, which is what GstCollectPads concludes
// itself once that frame is there, and the frame goes on at once. A frame
// with no line due needs none of this: the text, past the frame before,
// is not waited for.
//
// Two inputs both not waited for and both empty would read as the end of
// every input to GstCollectPads; that lasts here only between a line's turn
// and the line, which the same thread pushes next.
#pragma once

#include <gst/gst.h>

namespace wircam::recorder::collect_pads_turns {

// Whether `input` (a muxer's sink pad) is one of a GstCollectPads.
bool drive(GstPad* input);

// Before a line at `position` of `video`'s segment: `video` is not waited
// for, and says it has nothing up to just past it. True: the line may go
// in now (also when `video` has ended: it is not waited for then). False,
// with nothing changed: `video` has had no segment yet (a GAP event must
// not come before it), or `position` is none.
bool openForLine(GstPad* video, GstClockTime position);
// After the lines: `video` is waited for again, `text` is not.
void afterLines(GstPad* video, GstPad* text);

}  // namespace wircam::recorder::collect_pads_turns
