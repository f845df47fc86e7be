#include "app/live_servers_module.h"

#include <gmodule.h>

#include <atomic>
#include <cstdio>
#include <cstdlib>
#include <filesystem>

namespace wircam::recorder {

namespace {

std::atomic<const LiveServers*> loaded{nullptr};

Expected<const LiveServers*, std::string> open() {
  gchar* executable = g_file_read_link("/proc/self/exe", nullptr);
  if (!executable) return unexpected(std::string("cannot find the recorder's own executable"));
  // WIRCAM_SERVERS_MODULE: its path from the executable's folder (CMake).
  std::string path =
      (std::filesystem::path(executable).parent_path() / WIRCAM_SERVERS_MODULE).lexically_normal();
  g_free(executable);
  GModule* module = g_module_open(path.c_str(), G_MODULE_BIND_LOCAL);
  if (!module)
    return unexpected("the web, RTSP and Foxglove servers cannot be loaded: " +
                      std::string(g_module_error()));
  gpointer entry = nullptr;
  if (!g_module_symbol(module, kLiveServersEntry, &entry) || !entry)
    return unexpected(path + " is not wirc-recorder's servers module: " + g_module_error());
  g_module_make_resident(module);
  loaded = reinterpret_cast<const LiveServers* (*)()>(entry)();
  return loaded.load();
}

}  // namespace

Expected<const LiveServers*, std::string> liveServers() {
  static const Expected<const LiveServers*, std::string> opened = open();
  return opened;
}

void endProcess(int code) {
  if (const LiveServers* servers = loaded; servers && servers->busyAtExit()) {
    std::fflush(nullptr);
    std::_Exit(code);
  }
  std::exit(code);
}

}  // namespace wircam::recorder
