#include "app/live_servers_module.h"

#include <gmodule.h>

#include <filesystem>

namespace wircam::recorder {

namespace {

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
  return reinterpret_cast<const LiveServers* (*)()>(entry)();
}

}  // namespace

Expected<const LiveServers*, std::string> liveServers() {
  static const Expected<const LiveServers*, std::string> opened = open();
  return opened;
}

}  // namespace wircam::recorder
