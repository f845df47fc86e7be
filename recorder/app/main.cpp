// wirc-recorder: records WiRC cameras into segmented files with telemetry.
#include <gst/gst.h>

#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

#include "app/live_servers_module.h"
#include "app/open_files_check.h"
#include "app/recorder_options.h"
#include "app/slice_allocator.h"
#include "app/supervisor.h"
#include "camera/disk_writer.h"
#include "common/open_file_limit.h"

namespace {

// Raises this process's limit of open files as far as it may go, and says
// so when even that is short for the cameras asked for.
void raiseOpenFileLimitFor(const wircam::recorder::RecorderOptions& options) {
  uint64_t cameras = 0;  // (a device's list holds the --camera default when it named none)
  for (const auto& device : options.devices) cameras += device.cameras.size();
  if (auto shortfall = wircam::recorder::openFilesShortfall(cameras, wircam::raiseOpenFileLimit()))
    std::fprintf(stderr, "wirc-recorder: %s\n", shortfall->c_str());
}

}  // namespace

int main(int argc, char** argv) {
  using namespace wircam::recorder;
  useMallocForSlices(argv);
  // A reload parses the same command line again (gst_init takes its own
  // options out of argv, so a copy).
  std::vector<std::string> words(argv, argv + argc);
  auto reread = [words]() mutable {
    std::vector<char*> again;
    for (auto& word : words) again.push_back(word.data());
    again.push_back(nullptr);
    return parseOptions(static_cast<int>(words.size()), again.data());
  };
  auto options = parseOptions(argc, argv);
  if (!options) {
    if (options.error() == "help") {
      std::fputs(usage().c_str(), stdout);
      return 0;
    }
    std::fprintf(stderr, "wirc-recorder: %s (see wirc-recorder --help)\n", options.error().c_str());
    return 2;
  }
  raiseOpenFileLimitFor(*options);
  // The plugins of an uninstalled build sit beside bin/ in gst-plugins/.
  auto plugins =
      std::filesystem::canonical("/proc/self/exe").parent_path().parent_path() / "gst-plugins";
  if (std::filesystem::exists(plugins)) {
    const char* path = g_getenv("GST_PLUGIN_PATH");
    std::string joined = plugins.string() + (path ? ":" + std::string(path) : "");
    g_setenv("GST_PLUGIN_PATH", joined.c_str(), TRUE);
  }
  gst_init(&argc, &argv);
  auto supervisor = Supervisor::create(*options, reread);
  if (!supervisor) {
    std::fprintf(stderr, "wirc-recorder: %s\n", supervisor.error().c_str());
    return 1;
  }
  int code = (*supervisor)->run();
  supervisor->reset();
  DiskWriter::finishAll();
  endProcess(code);
}
