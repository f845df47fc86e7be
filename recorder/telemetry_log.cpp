#include "telemetry_log.h"

namespace wircam::recorder {

bool TelemetryLog::open(const std::string& segment) {
  close();
  auto dot = segment.rfind('.');
  path_ = (dot == std::string::npos ? segment : segment.substr(0, dot)) + ".jsonl";
  file_ = std::fopen(path_.c_str(), "w");
  opened_ = true;
  for (const auto& line : early_) writeLine(line);
  early_.clear();
  return file_ != nullptr;
}

void TelemetryLog::close() {
  if (file_) std::fclose(file_);
  file_ = nullptr;
}

void TelemetryLog::write(const std::string& json) {
  if (!opened_) {
    if (early_.size() < kMaxEarlyLines) early_.push_back(json);
    return;
  }
  writeLine(json);
}

void TelemetryLog::writeLine(const std::string& json) {
  if (!file_) return;
  std::fputs(json.c_str(), file_);
  std::fputc('\n', file_);
  std::fflush(file_);
}

}  // namespace wircam::recorder
