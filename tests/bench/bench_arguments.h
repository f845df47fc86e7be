// A bench tool's positional arguments: each a number above 0, those left
// out taken from its defaults. Anything else (a word, 0, a negative, one
// too many, --help) prints the usage, and the tool exits 2 rather than
// measuring what it was not asked to.
#pragma once

#include <optional>
#include <vector>

namespace wircam::bench {

// argv[1]... as numbers, as many as `defaults` holds; nullopt after
// printing `usage` on stderr.
std::optional<std::vector<double>> positiveArguments(int argc, char** argv,
                                                     std::vector<double> defaults,
                                                     const char* usage);

}  // namespace wircam::bench
