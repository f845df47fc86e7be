// Reads a recorded segment back (its demuxer only, nothing decoded) for the
// recording index: its frames, how long it plays, its camera and UTC start
// (from its name, or its modification time less its length).
#pragma once

#include <filesystem>
#include <optional>

#include "record/recording_index.h"

namespace wircam::recorder {

// Nothing when the file holds no readable video (e.g. cut before its first
// frame).
std::optional<IndexEntry> inspectSegment(const std::filesystem::path& file);

}  // namespace wircam::recorder
