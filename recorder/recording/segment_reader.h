// Reads one recorded segment back, frame by frame, as the camera's bytes
// (its demuxer only: nothing decoded or re-encoded), with its sidecar.
#pragma once

#include <gst/gst.h>

#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "common/expected.h"

namespace wircam::recorder {

struct SegmentFrame {
  GstBuffer* buffer = nullptr;  // owned: the frame's bytes and flags
  int64_t ptsNs = 0;            // on the segment's timeline
  bool key = true;              // a decoder can start here (an IDR; every JPEG)
  SegmentFrame() = default;
  SegmentFrame(SegmentFrame&& other) noexcept;
  SegmentFrame& operator=(SegmentFrame&& other) noexcept;
  ~SegmentFrame();
};

class SegmentReader {
 public:
  static Expected<std::unique_ptr<SegmentReader>, std::string> open(
      const std::filesystem::path& video);
  ~SegmentReader();
  SegmentReader(const SegmentReader&) = delete;
  SegmentReader& operator=(const SegmentReader&) = delete;

  // The next frame; nothing at the end. A file that breaks off is an
  // error (what the demuxer said), after the frames before it.
  Expected<std::optional<SegmentFrame>, std::string> next();
  // The frames' caps (after the first frame), as the muxers want them.
  GstCaps* caps() const { return caps_; }

 private:
  SegmentReader() = default;
  GstElement* pipeline_ = nullptr;
  GstElement* sink_ = nullptr;
  GstCaps* caps_ = nullptr;
};

// Whether a recorded JPEG frame is whole: its end marker is there. The
// source never emits another, so one without it was damaged in the file
// (zeros where a power loss left its last blocks). Every reader of
// recordings refuses such a frame.
bool isWholeJpeg(GstBuffer* jpeg);

// The sidecar's lines (JSON text), in file order; none if it is missing.
std::vector<std::string> sidecarLines(const std::filesystem::path& video);

}  // namespace wircam::recorder
