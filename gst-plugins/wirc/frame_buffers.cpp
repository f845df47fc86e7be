#include "frame_buffers.h"

#include "gst_scoped.h"
#include "wirc/jpeg_info.h"
#include "wirc_bus_messages.h"

namespace wircam::gst {

namespace {

struct WrappedFrame {
  wirc::FrameBuffer buffer;
  std::shared_ptr<wirc::FrameBufferReturns> returns;
};

}  // namespace

GstBuffer* wrapFrame(wirc::AssembledFrame&& frame,
                     std::shared_ptr<wirc::FrameBufferReturns> returns) {
  auto* owned = new WrappedFrame{std::move(frame.data), std::move(returns)};
  auto& bytes = owned->buffer;
  return gst_buffer_new_wrapped_full(
      GST_MEMORY_FLAG_READONLY, bytes.data(), bytes.capacity(), 0, bytes.size(), owned,
      [](gpointer data) {
        std::unique_ptr<WrappedFrame> done(static_cast<WrappedFrame*>(data));
        if (done->returns) done->returns->put(std::move(done->buffer));
      });
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
