// GET /metrics: the recorder in Prometheus's text exposition format (0.0.4),
// written here rather than with prometheus-cpp: the format is a few lines of
// text per family, the values already exist (each camera's report, the
// supervisor's totals), and a registry of live metric objects would only
// copy them. Names follow Prometheus's conventions: base units (seconds,
// bytes, volts), _total for counters, a `stream` label per camera.
#pragma once

#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "status/camera_report.h"

namespace wircam::recorder {

// What the supervisor adds up per camera since it started.
struct RecordedTotals {
  uint64_t segmentsClosed = 0, bytes = 0, frames = 0;
  uint64_t hookFailures = 0;  // runs of --on-segment-closed that failed
};

struct RecorderMetrics {
  std::string version;
  std::vector<CameraReport> cameras;
  std::map<std::string, RecordedTotals> recorded;  // by camera name
  uint64_t diskFreeBytes = 0;
  std::optional<uint64_t> mqttPublished, mqttDropped;  // with --mqtt
  std::optional<bool> mqttConnected;
  uint64_t httpConnections = 0;
  // With --foxglove: clients connected, refused over the limit, messages
  // sent and dropped (a slow client's).
  struct Foxglove {
    uint64_t clients = 0, refused = 0, sent = 0, dropped = 0;
  };
  std::optional<Foxglove> foxglove;
};

std::string prometheusText(const RecorderMetrics& metrics);

// A label value as the format quotes it: \, " and newlines escaped.
std::string escapedLabel(const std::string& value);

}  // namespace wircam::recorder
