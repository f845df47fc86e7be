#include "record/telemetry_log.h"

namespace wircam::recorder {

TelemetryLog::TelemetryLog(const std::string& segment) : path_(pathFor(segment)) {}

TelemetryLog::~TelemetryLog() {
  if (file_) std::fclose(file_);
}

std::string TelemetryLog::pathFor(const std::string& segment) {
  auto dot = segment.rfind('.');
  auto slash = segment.rfind('/');
  bool hasExtension = dot != std::string::npos && (slash == std::string::npos || dot > slash);
  return (hasExtension ? segment.substr(0, dot) : segment) + ".jsonl";
}

bool TelemetryLog::create() {
  // Appending: a late line for a segment whose sidecar was closed reopens it.
  if (!file_) file_ = std::fopen(path_.c_str(), "a");
  return file_ != nullptr;
}

bool TelemetryLog::write(const std::string& json) {
  if (!create()) return false;
  std::fputs(json.c_str(), file_);
  std::fputc('\n', file_);
  std::fflush(file_);
  return true;
}

}  // namespace wircam::recorder
