#include "frame_buffers.h"

#include "gst_scoped.h"
#include "wirc/jpeg_info.h"
#include "wirc_bus_messages.h"

namespace wircam::gst {

GstBuffer* wrapFrame(wirc::AssembledFrame&& frame) {
  auto* owned = new wirc::FrameBuffer(std::move(frame.data));
  return gst_buffer_new_wrapped_full(
      GST_MEMORY_FLAG_READONLY, owned->data(), owned->capacity(), 0, owned->size(), owned,
      [](gpointer data) { delete static_cast<wirc::FrameBuffer*>(data); });
}

GstCaps* jpegCapsIfChanged(GstBuffer* frame, int& width, int& height) {
  ScopedBufferMap map(frame, GST_MAP_READ);
  if (!map) return nullptr;
  auto info = wirc::readJpegInfo({map.data(), map.size()});
  if (!info || (info->width == width && info->height == height)) return nullptr;
  width = info->width;
  height = info->height;
  // The device sends at its own pace: the frame rate is variable (0/1).
  return gst_caps_new_simple("image/jpeg", "width", G_TYPE_INT, width, "height", G_TYPE_INT, height,
                             "framerate", GST_TYPE_FRACTION, 0, 1, "parsed", G_TYPE_BOOLEAN, TRUE,
                             nullptr);
}
GstStructure* statsStructure(const wirc::AssemblerStats& s, uint64_t foreignPackets) {
  return gst_structure_new(wircam::bus::Stats::kName, "packets", G_TYPE_UINT64, s.packets, "bytes",
                           G_TYPE_UINT64, s.payloadBytes, "frames-complete", G_TYPE_UINT64,
                           s.framesComplete, "frames-incomplete", G_TYPE_UINT64, s.framesDropped(),
                           "frames-timed-out", G_TYPE_UINT64, s.framesTimedOut, "frames-superseded",
                           G_TYPE_UINT64, s.framesSuperseded, "frames-late", G_TYPE_UINT64,
                           s.packetsLate, "packets-duplicate", G_TYPE_UINT64, s.packetsDuplicate,
                           "packets-invalid", G_TYPE_UINT64, s.packetsInvalid, "packets-foreign",
                           G_TYPE_UINT64, foreignPackets, "keepalives", G_TYPE_UINT64, s.keepalives,
                           "sender-restarts", G_TYPE_UINT64, s.senderRestarts, nullptr);
}

}  // namespace wircam::gst
