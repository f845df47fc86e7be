// wirc-recorder's outside input: command-line option values, a --config
// file, and request paths for its web server. The first byte says which.
#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "app/recorder_options.h"
#include "http/http_routes.h"

using namespace wircam::recorder;

namespace {

void options(std::string_view input) {
  // NUL-separated words after the program name.
  std::vector<std::string> words = {"wirc-recorder"};
  size_t start = 0;
  while (start <= input.size()) {
    size_t end = input.find('\0', start);
    if (end == std::string_view::npos) end = input.size();
    words.emplace_back(input.substr(start, end - start));
    start = end + 1;
  }
  std::vector<char*> argv;
  for (auto& word : words) argv.push_back(word.data());
  argv.push_back(nullptr);
  opterr = 0;
  parseOptions(static_cast<int>(words.size()), argv.data());
}

void config(std::string_view input) {
  static std::string path = "/tmp/wircam-fuzz-config-" + std::to_string(getpid()) + ".ini";
  if (FILE* file = std::fopen(path.c_str(), "wb")) {
    std::fwrite(input.data(), 1, input.size(), file);
    std::fclose(file);
  }
  std::string configArg = path;
  char program[] = "wirc-recorder", flag[] = "--config";
  char* argv[] = {program, flag, configArg.data(), nullptr};
  opterr = 0;
  parseOptions(3, argv);
}

void route(std::string_view input) {
  auto found = routeOf(input);
  if (found.kind == Route::Kind::Recording && isRecordingName(found.name) &&
      (found.name.find('/') != std::string::npos || found.name.starts_with(".")))
    std::abort();  // a name that could leave the recordings folder
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  if (size == 0) return 0;
  std::string_view input(reinterpret_cast<const char*>(data) + 1, size - 1);
  switch (data[0] % 3) {
    case 0:
      options(input);
      break;
    case 1:
      config(input);
      break;
    default:
      route(input);
  }
  return 0;
}
