#include "hex.h"

#include <cctype>

namespace wircam::cli {

Expected<std::vector<uint8_t>, std::string> parseHex(std::string_view text) {
  std::vector<uint8_t> bytes;
  int high = -1;  // the first digit of a byte, while waiting for the second
  for (char c : text) {
    auto u = static_cast<unsigned char>(c);
    if (std::isspace(u) || c == ',' || c == ':') continue;
    if (!std::isxdigit(u)) return unexpected(std::string("not hex: '") + c + "'");
    int digit = std::isdigit(u) ? c - '0' : std::tolower(u) - 'a' + 10;
    if (high < 0) {
      high = digit;
    } else {
      bytes.push_back(static_cast<uint8_t>(high << 4 | digit));
      high = -1;
    }
  }
  if (high >= 0) return unexpected(std::string("an odd number of hex digits"));
  return bytes;
}

}  // namespace wircam::cli
