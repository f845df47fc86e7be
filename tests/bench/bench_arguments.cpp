#include "bench_arguments.h"

#include <cstdio>
#include <cstdlib>

namespace wircam::bench {

std::optional<std::vector<double>> positiveArguments(int argc, char** argv,
                                                     std::vector<double> defaults,
                                                     const char* usage) {
  bool understood = static_cast<size_t>(argc - 1) <= defaults.size();
  for (int i = 1; understood && i < argc; ++i) {
    char* end = nullptr;
    double value = std::strtod(argv[i], &end);
    understood = end != argv[i] && *end == '\0' && value > 0;
    if (understood) defaults[static_cast<size_t>(i - 1)] = value;
  }
  if (understood) return defaults;
  std::fprintf(stderr, "%s\n", usage);
  return std::nullopt;
}

}  // namespace wircam::bench
