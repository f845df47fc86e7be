// Whether a segment file was cut short: its last element (a Matroska
// cluster or block, an MP4 box) says it is longer than what is left of the
// file. The demuxers end such a file quietly at its last whole frame; a
// user should hear that the rest was lost.
#pragma once

#include <filesystem>

namespace wircam::recorder {

bool endsMidElement(const std::filesystem::path& video);

}  // namespace wircam::recorder
