#include "fleet/recorder_id.h"

#include <glib.h>

#include <algorithm>
#include <cctype>
#include <fstream>

namespace wircam::recorder {

namespace {

// What an MQTT topic level and a URL can carry as they are.
bool isPlainId(const std::string& id) {
  return !id.empty() && id.size() <= 64 && std::all_of(id.begin(), id.end(), [](char c) {
    return std::isalnum(static_cast<unsigned char>(c)) || c == '-' || c == '_';
  });
}

}  // namespace

Expected<std::string, std::string> recorderId(const std::filesystem::path& folder) {
  auto path = folder / kRecorderIdFile;
  std::string id;
  if (std::ifstream in(path); in && std::getline(in, id)) {
    if (isPlainId(id)) return id;
    return unexpected(path.string() + " holds no recorder id (letters, digits, - and _, 64 at " +
                      "most): mend it or delete it for a new one");
  }
  gchar* made = g_uuid_string_random();
  id = made;
  g_free(made);
  std::ofstream out(path, std::ios::trunc);
  out << id << "\n";
  if (!out.flush()) return unexpected("cannot write the recorder id to " + path.string());
  return id;
}

}  // namespace wircam::recorder
