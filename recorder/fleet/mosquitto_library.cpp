#include "fleet/mosquitto_library.h"

#include <gmodule.h>

namespace wircam::recorder {

namespace {

constexpr char kSoname[] = "libmosquitto.so.1";

Expected<const MosquittoLibrary*, std::string> open() {
  // Kept open for the process's life: a client may start again after the last ended.
  GModule* module = g_module_open(kSoname, G_MODULE_BIND_LOCAL);
  if (!module)
    return unexpected(std::string("MQTT needs ") + kSoname +
                      " (Debian: libmosquitto1): " + g_module_error());
  static MosquittoLibrary library;
  bool complete = true;
#define WIRCAM_MOSQUITTO_LOOKUP(member, symbol) \
  complete =                                    \
      complete && g_module_symbol(module, #symbol, reinterpret_cast<gpointer*>(&library.member));
  WIRCAM_MOSQUITTO_FUNCTIONS(WIRCAM_MOSQUITTO_LOOKUP)
#undef WIRCAM_MOSQUITTO_LOOKUP
  if (!complete)
    return unexpected(std::string(kSoname) + " lacks a function wircam needs: " + g_module_error());
  library.libInit();
  return &library;
}

}  // namespace

Expected<const MosquittoLibrary*, std::string> mosquittoLibrary() {
  static const Expected<const MosquittoLibrary*, std::string> opened = open();
  return opened;
}

}  // namespace wircam::recorder
