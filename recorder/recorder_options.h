// What wirc-recorder was asked to do, read from its command line.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "common/expected.h"

namespace wircam::recorder {

struct DeviceTarget {
  std::string host;  // empty: discover
  uint16_t port = 1984;
  std::string label;           // in file names: the host, or the config section's name
  std::vector<int> cameras;    // empty: the recorder-wide --camera list
  std::optional<bool> follow;  // unset: the recorder-wide --follow
};

struct RecorderOptions {
  std::vector<DeviceTarget> devices;
  std::vector<int> cameras;  // default {0}
  std::string outDir = ".";
  double segmentSeconds = 60;
  std::string detectFamily;  // empty: no detection
  bool follow = false;       // needs detectFamily
  std::optional<double> duration;
  double statusSeconds = 1;
  uint64_t maxBytes = 0;  // retention: 0 = unlimited
  uint64_t minFree = 0;
};

// The options, or an error message naming the bad argument; --help text in
// `usage()`. `--config FILE` reads a GKeyFile first; options given on the
// command line after it override its [recorder] group.
Expected<RecorderOptions, std::string> parseOptions(int argc, char** argv);
const char* usage();

}  // namespace wircam::recorder
