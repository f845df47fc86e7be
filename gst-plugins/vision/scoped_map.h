// Buffer and video-frame mappings that unmap themselves when they go out of
// scope, so that no early return can leave one mapped.
#pragma once

#include <gst/gst.h>
#include <gst/video/video.h>

namespace wircam::gst {

// Holds a reference while mapped: the buffer may be released by its owner
// (a decoder's finished frame) before the scope ends.
class ScopedBufferMap {
 public:
  ScopedBufferMap(GstBuffer* buffer, GstMapFlags flags)
      : buffer_(gst_buffer_ref(buffer)), mapped_(gst_buffer_map(buffer, &info_, flags)) {}
  ~ScopedBufferMap() {
    if (mapped_) gst_buffer_unmap(buffer_, &info_);
    gst_buffer_unref(buffer_);
  }
  ScopedBufferMap(const ScopedBufferMap&) = delete;
  ScopedBufferMap& operator=(const ScopedBufferMap&) = delete;

  explicit operator bool() const { return mapped_; }
  const guint8* data() const { return info_.data; }
  gsize size() const { return info_.size; }

 private:
  GstBuffer* buffer_;
  GstMapInfo info_{};
  bool mapped_;
};

class ScopedVideoFrameMap {
 public:
  ScopedVideoFrameMap(const GstVideoInfo* info, GstBuffer* buffer, GstMapFlags flags)
      : mapped_(gst_video_frame_map(&frame_, info, buffer, flags)) {}
  ~ScopedVideoFrameMap() {
    if (mapped_) gst_video_frame_unmap(&frame_);
  }
  ScopedVideoFrameMap(const ScopedVideoFrameMap&) = delete;
  ScopedVideoFrameMap& operator=(const ScopedVideoFrameMap&) = delete;

  explicit operator bool() const { return mapped_; }
  GstVideoFrame* operator->() { return &frame_; }
  GstVideoFrame* get() { return &frame_; }

 private:
  GstVideoFrame frame_{};
  bool mapped_;
};

}  // namespace wircam::gst
