// What the export tests share: wirc-export's command line for a
// recordings folder, and the recorder's times moved by milliseconds.
#pragma once

#include <cstdint>
#include <cstdio>
#include <ctime>
#include <filesystem>
#include <string>

namespace wircam::testing {

inline std::string exportCommand(const std::filesystem::path& recordings, const std::string& camera,
                                 const std::string& rest) {
  return std::string(WIRC_EXPORT) + " --recordings '" + recordings.string() + "' --camera " +
         camera + " " + rest;
}

// "2026-11-24T14:59:35.467Z" moved by `deltaMs` (the recorder writes
// milliseconds), in the same form.
inline std::string shiftedIso(const std::string& iso, int64_t deltaMs) {
  std::tm parts{};
  if (!strptime(iso.c_str(), "%Y-%m-%dT%H:%M:%S", &parts)) return iso;
  int64_t ms = int64_t{timegm(&parts)} * 1000 + std::stoi(iso.substr(20, 3)) + deltaMs;
  time_t seconds = static_cast<time_t>(ms / 1000);
  gmtime_r(&seconds, &parts);
  char whole[24], shifted[32];
  std::strftime(whole, sizeof whole, "%Y-%m-%dT%H:%M:%S", &parts);
  std::snprintf(shifted, sizeof shifted, "%s.%03dZ", whole, static_cast<int>(ms % 1000));
  return shifted;
}

}  // namespace wircam::testing
