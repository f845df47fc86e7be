// Which recorded segments of one camera a time range holds, and their
// times: from the folder's index.json (rebuilt from the files, as the
// recorder does at start-up, when it is missing). Read by the export and
// the replay alike.
#pragma once

#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "common/expected.h"

namespace wircam::recorder {

// "2026-11-24T14:59:35Z", "2026-11-24T14:59:35.467+01:00" (ISO 8601 with a
// zone; without one, local time) → nanoseconds since the Unix epoch.
std::optional<int64_t> parseIsoTime(const std::string& text);
// Nanoseconds since the epoch → "2026-11-24T14:59:35.467Z".
std::string isoTimeOf(int64_t unixNs);

struct ExportSegment {
  std::filesystem::path video;  // the segment file
  int64_t startNs = 0;          // its first frame, UTC ns
  int64_t durationNs = 0;
  uint64_t frames = 0;
  std::string recorder;  // a fleet's recorder it came from, or empty
};

struct ExportSelection {
  std::vector<ExportSegment> segments;  // oldest first
  // What the user should know: segments still being written, an index
  // rebuilt.
  std::vector<std::string> notes;
};

// The segments of `camera` in `folder` that overlap [start, end] (either
// open-ended). Errors: an unknown camera (naming those there are), nothing
// in the range, an unreadable folder.
Expected<ExportSelection, std::string> selectSegments(const std::filesystem::path& folder,
                                                      const std::string& camera,
                                                      std::optional<int64_t> start,
                                                      std::optional<int64_t> end);

}  // namespace wircam::recorder
