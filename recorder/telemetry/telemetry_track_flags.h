// Marks the telemetry track of a finished file as neither default nor
// forced, so that players do not show its JSON as subtitles.
// MP4: the text track's header (tkhd) loses its "enabled" flag, in place.
// Matroska: matroskamux (GStreamer 1.22) writes no FlagDefault, which
// Matroska reads as "default", and cannot be told otherwise. So the recorder names
// the track with a longer placeholder, and this rewrites that one element,
// in place and at the same size, as the name, FlagDefault 0, FlagForced 0
// and a Void element filling the rest, and the same name in the title tag
// at the end of the file: nothing else in the file moves.
#pragma once

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <string_view>
#include <vector>

namespace wircam::recorder {

// What the recorder names the track in the muxer (a file the recorder did
// not finish keeps it): room for the name, the flags and a Void.
inline constexpr std::string_view kTelemetryTrackPlaceholder = "telemetry-json-lines";
// What it is called once marked.
inline constexpr std::string_view kTelemetryTrackName = "telemetry";

enum class TrackContainer { kMatroska, kMp4 };

// True if the track was found and marked; false for a file without it (not
// a recording, marked already, or cut before its header), left as it was.
// The container by the file's extension (.mp4, else Matroska), or as given
// (a file written under another name until it is whole).
bool markTelemetryTrack(const std::filesystem::path& file);
bool markTelemetryTrack(const std::filesystem::path& file, TrackContainer container);

// The same on a stream's first bytes, before they leave (a streamed export
// cannot go back): its header, the tracks (and a streamable Matroska's
// tags) included, is in the first kTelemetryTrackHeaderBytes, before the
// first cluster or fragment. True if marked.
inline constexpr size_t kTelemetryTrackHeaderBytes = 64 * 1024;
bool markTelemetryTrackInHeader(std::vector<uint8_t>& header, TrackContainer container);

}  // namespace wircam::recorder
