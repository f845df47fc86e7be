// RAII over GStreamer's C resources, for every part of wircam (elements,
// recorder, tools): an object's lock and buffer or video-frame mappings that
// end with their scope, so that no early return leaves one held. Internal:
// not installed with the public headers.
#pragma once

#include <gst/gst.h>
#include <gst/video/video.h>

#include <string_view>

namespace wircam::gst {

// Holds a GstObject's lock for a scope (as libcamera's GLibLocker does).
class GLibLocker {
 public:
  explicit GLibLocker(gpointer object) : object_(GST_OBJECT(object)) { GST_OBJECT_LOCK(object_); }
  ~GLibLocker() { GST_OBJECT_UNLOCK(object_); }
  GLibLocker(const GLibLocker&) = delete;
  GLibLocker& operator=(const GLibLocker&) = delete;

 private:
  GstObject* object_;
};

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
  // The bytes as text (a JPEG for a string body, say).
  std::string_view view() const { return {reinterpret_cast<const char*>(info_.data), info_.size}; }

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
