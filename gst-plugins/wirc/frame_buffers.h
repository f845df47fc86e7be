// Turning assembled frames into GstBuffers without copying them, and the
// stats structure both wircsrc and wircdepay expose.
#pragma once

#include <gst/gst.h>

#include <memory>

#include "wirc/frame_assembler.h"
#include "wirc/frame_buffer_returns.h"

namespace wircam::gst {

// Hands the frame's memory to a GstBuffer; when the buffer is freed it goes
// to `returns` (to be filled again), or is freed too without one.
GstBuffer* wrapFrame(wirc::AssembledFrame&& frame,
                     std::shared_ptr<wirc::FrameBufferReturns> returns = nullptr);

// New image/jpeg caps when the frame's size (read from its SOF) differs from
// width × height, which are updated; nullptr when nothing changed.
GstCaps* jpegCapsIfChanged(GstBuffer* frame, int& width, int& height);

// "wirc-stats": the assembler's counters under the names users see.
GstStructure* statsStructure(const wirc::AssemblerStats& stats, uint64_t foreignPackets);

}  // namespace wircam::gst
