// One camera's time range, from its recorded segments into one file: the
// frames untouched on one timeline from 0 (an outage stays a gap), the
// sidecars' lines merged at their times, and the same lines, re-based, in a
// .jsonl beside the file.
#pragma once

#include <filesystem>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "common/expected.h"
#include "recording/segment_selection.h"

namespace wircam::recorder {

enum class ExportFormat { kMkv, kMp4, kMcap };
std::optional<ExportFormat> exportFormatOf(const std::string& name);  // "mkv", "mp4", "mcap"
const char* exportFormatName(ExportFormat format);                    // and back

struct ExportRequest {
  std::filesystem::path recordings;
  std::string camera;
  std::optional<int64_t> start, end;  // UTC ns; open-ended without
  ExportFormat format = ExportFormat::kMkv;
  std::filesystem::path out;
  // With a descriptor: the file streamed to it as it is made (see
  // ExportTarget), `out` only naming it, and no .jsonl.
  int stream = -1;
  // Segments may overlap in time (a fleet's: two recorders held the vehicle
  // at once while it moved): a frame of another recorder's segment less
  // than half a frame after the last one taken is the same moment seen
  // twice, and left out. (One recorder's segments follow each other.)
  bool overlapping = false;
};

struct ExportReport {
  uint64_t frames = 0, lines = 0, segments = 0;
  int64_t firstUtcNs = 0, lastUtcNs = 0;
  std::vector<std::string> notes;  // segments skipped or left out, and why
};

// Frames done of about how many, and the file's bytes so far; false stops
// the export (a client gone).
using ExportProgress = std::function<bool(uint64_t done, uint64_t total, uint64_t bytes)>;

// What is known as the first frame goes in, before any byte of the file:
// what a streamed response says in its headers.
struct ExportStart {
  int64_t firstUtcNs = 0;
  int64_t lastUtcNs = 0;           // as planned: the range's end or the last segment's
  std::vector<std::string> notes;  // left out so far
};
using ExportStarted = std::function<void(const ExportStart&)>;

struct ExportError {
  enum class Kind {
    kNothing,      // an unknown camera, no frame in the range
    kUnsupported,  // the format cannot hold the camera's frames (JPEG in MP4)
    kFailed,       // the file could not be written
    kCancelled,    // the progress said stop
  };
  Kind kind;
  std::string message;
};

// For names of files: "2026-11-24T14:59:35.467Z" → "20261124T145935Z",
// as the segments are named; and text with anything but letters, digits,
// '-' and '.' made '_'.
std::string compactTimeOf(int64_t unixNs);
std::string fileNamePart(const std::string& text);

// What an export's file is called until it is whole (and its .jsonl's,
// likewise): `out` with ".partial" added.
std::filesystem::path partialPathOf(const std::filesystem::path& out);

// On an error nothing is left at `out` (what was streamed is the reader's).
Expected<ExportReport, ExportError> exportRange(const ExportRequest& request,
                                                const ExportProgress& progress = {},
                                                const ExportStarted& started = {});

}  // namespace wircam::recorder
