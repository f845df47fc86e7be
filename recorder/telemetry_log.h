// The JSON-lines sidecar of one stream's current segment: one object per
// event, each with the pipeline running time ("pts") it belongs to.
#pragma once

#include <cstdio>
#include <string>
#include <vector>

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
  // so a crash loses at most the line being written. Lines that come
  // before the first segment opens (the login, the control right) wait for
  // it, up to kMaxEarlyLines.
  void write(const std::string& json);
  static constexpr size_t kMaxEarlyLines = 256;
  const std::string& path() const { return path_; }

 private:
  void writeLine(const std::string& json);

  FILE* file_ = nullptr;
  std::string path_;
  bool opened_ = false;  // a segment has been opened once
  std::vector<std::string> early_;
};

}  // namespace wircam::recorder
