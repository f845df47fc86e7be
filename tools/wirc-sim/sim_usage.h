// wirc-sim's --help text: every option, apart from the parsing in main.cpp.
#pragma once

namespace wircam::sim {

extern const char* const kUsage;

}  // namespace wircam::sim
