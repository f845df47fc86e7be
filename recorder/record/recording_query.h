// Which recordings a request asks for (GET /api/recordings and
// /api/fleet/recordings: ?camera=NAME&vehicle=SERIAL_OR_NAME&day=YYYY-MM-DD),
// decided on the index's entries: a camera's name exactly, a vehicle by the
// serial or name its device gave, a UTC day by overlap (a segment across
// midnight belongs to both days).
#pragma once

#include <cstdint>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>

#include "common/expected.h"

namespace wircam::recorder {

struct RecordingQuery {
  std::string camera;                     // empty: any
  std::string vehicle;                    // empty: any
  std::optional<int64_t> dayStartUnixMs;  // the UTC day's midnight, or any day
  bool any() const { return camera.empty() && vehicle.empty() && !dayStartUnixMs; }
};

// The query's values as given (null: absent); why one is refused.
Expected<RecordingQuery, std::string> recordingQueryOf(const char* camera, const char* vehicle,
                                                       const char* day);
// The query again as a URL's query string ("" or "?camera=...&day=...").
std::string queryString(const RecordingQuery& query);

// `entry` as the index gives it (record/recording_index.h's toJson).
bool matches(const RecordingQuery& query, const nlohmann::json& entry);

// "2026-11-28T08:19:49.898Z" as ms since the epoch, or nullopt.
std::optional<int64_t> unixMsOfUtc(const std::string& iso);

}  // namespace wircam::recorder
