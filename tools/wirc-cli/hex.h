// Hex text as wirc-cli reads it ("aa bb 01", "AA:BB:01", "aabb01"): the
// bytes, or why not.
#pragma once

#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "common/expected.h"

namespace wircam::cli {

Expected<std::vector<uint8_t>, std::string> parseHex(std::string_view text);

}  // namespace wircam::cli
