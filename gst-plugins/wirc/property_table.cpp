#include "property_table.h"

#include <algorithm>
#include <cctype>

namespace wircam::gst {

const char* nickOf(const char* name) {
  std::string nick = name;
  std::replace(nick.begin(), nick.end(), '-', ' ');
  nick[0] = static_cast<char>(std::toupper(static_cast<unsigned char>(nick[0])));
  return g_intern_string(nick.c_str());  // static, as G_PARAM_STATIC_STRINGS wants
}

}  // namespace wircam::gst
