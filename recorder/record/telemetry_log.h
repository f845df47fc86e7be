// The JSON-lines sidecar of one segment: one object per line, appended and
// flushed as it comes, so a crash loses at most the line being written.
#pragma once

#include <cstdio>
#include <string>

namespace wircam::recorder {

class TelemetryLog {
 public:
  // The sidecar of the video file `segment`: the same name, ".jsonl".
  explicit TelemetryLog(const std::string& segment);
  TelemetryLog(const TelemetryLog&) = delete;
  TelemetryLog& operator=(const TelemetryLog&) = delete;
  ~TelemetryLog();

  static std::string pathFor(const std::string& segment);
  // Creates the file (appending if it exists); false if it cannot be.
  bool create();
  // Creates the file first if need be; false if it cannot be written.
  bool write(const std::string& json);
  const std::string& path() const { return path_; }

 private:
  std::string path_;
  FILE* file_ = nullptr;
};

}  // namespace wircam::recorder
