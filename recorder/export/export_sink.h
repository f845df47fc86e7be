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
};

}  // namespace wircam::recorder
