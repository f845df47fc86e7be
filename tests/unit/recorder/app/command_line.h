// wirc-recorder's command line as the options tests give it: the words after
// the program's name.
#pragma once

#include <string>
#include <vector>

#include "app/recorder_options.h"

namespace wircam::recorder {

inline Expected<RecorderOptions, std::string> parse(std::vector<std::string> words) {
  words.insert(words.begin(), "wirc-recorder");
  std::vector<char*> argv;
  for (auto& word : words) argv.push_back(word.data());
  argv.push_back(nullptr);
  return parseOptions(static_cast<int>(words.size()), argv.data());
}

}  // namespace wircam::recorder
