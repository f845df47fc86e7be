// The recorder's id in the fleet: made once, kept beside its recordings
// (DIR/.wircam-recorder-id), so that it survives restarts and stays with
// the history it names; a folder copied to another machine takes its
// recorder's identity along.
#pragma once

#include <filesystem>
#include <string>

#include "common/expected.h"

namespace wircam::recorder {

inline constexpr const char* kRecorderIdFile = ".wircam-recorder-id";

// The id stored in `folder`, or a new one (a random UUID) stored there.
Expected<std::string, std::string> recorderId(const std::filesystem::path& folder);

}  // namespace wircam::recorder
