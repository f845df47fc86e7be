// The JSON-lines sidecar of one stream's current segment: one object per
// event, each with the pipeline running time ("pts") it belongs to.
#pragma once

#include <cstdio>
#include <string>

namespace wircam::recorder {

class TelemetryLog {
 public:
  TelemetryLog() = default;
  TelemetryLog(const TelemetryLog&) = delete;
  TelemetryLog& operator=(const TelemetryLog&) = delete;
  ~TelemetryLog() { close(); }

  // Starts the sidecar of a new segment (`segment` is the video's path).
  bool open(const std::string& segment);
  void close();
  // `json` is one complete object; it is written as one line and flushed,
  // so a crash loses at most the line being written.
  void write(const std::string& json);
  const std::string& path() const { return path_; }

 private:
  FILE* file_ = nullptr;
  std::string path_;
};

}  // namespace wircam::recorder
