// Whether this process may open the files its cameras need: a camera holds
// about a dozen (12 measured at 64: its sockets and its link's, its
// pipeline's wake-ups, the files it writes), and a camera that cannot open
// one does not start. Asked at the start and at each reload that adds
// cameras.
#pragma once

#include <cstdint>
#include <optional>
#include <string>

namespace wircam::recorder {

// What to say when `cameras` may need more open files than `limit`, with
// the limit to set; nothing when they fit.
std::optional<std::string> openFilesShortfall(uint64_t cameras, uint64_t limit);

}  // namespace wircam::recorder
