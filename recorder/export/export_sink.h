// Where an export goes: one file, fed the frames and the telemetry lines of
// a time range in time order, each with its time on the export's timeline
// (from 0 at the first frame) and its UTC.
#pragma once

#include <gst/gst.h>

#include <cstdint>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>

namespace wircam::recorder {

// Where an export's file goes: to `path`, or, with a `stream` descriptor,
// out as its bytes are made (which no muxer can go back over: Matroska
// without its index, MP4 fragmented; `path` then names it in messages).
struct ExportTarget {
  std::string path;
  int stream = -1;
};

class ExportSink {
 public:
  virtual ~ExportSink() = default;
  // Before the first frame, with its caps. An error in words, or nothing.
  virtual std::optional<std::string> start(GstCaps* caps) = 0;
  // `buffer` is borrowed: the camera's bytes, untouched.
  virtual std::optional<std::string> frame(GstBuffer* buffer, int64_t ptsNs, int64_t utcNs,
                                           bool key) = 0;
  virtual std::optional<std::string> line(const nlohmann::json& line, int64_t ptsNs,
                                          int64_t utcNs) = 0;
  // Everything written and the file closed.
  virtual std::optional<std::string> finish() = 0;
  // The file's bytes so far (for progress).
  virtual uint64_t bytesWritten() = 0;
};

}  // namespace wircam::recorder
