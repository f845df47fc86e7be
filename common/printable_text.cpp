#include "common/printable_text.h"

#include <cstdio>

namespace wircam {

namespace {

// Whether `bytes` is UTF-8 by its byte pattern (overlong forms are not
// looked for: the text is only shown, never interpreted).
bool isUtf8(std::string_view bytes) {
  for (size_t i = 0; i < bytes.size();) {
    auto lead = static_cast<unsigned char>(bytes[i]);
    size_t extra = lead < 0x80             ? 0
                   : (lead & 0xE0) == 0xC0 ? 1
                   : (lead & 0xF0) == 0xE0 ? 2
                   : (lead & 0xF8) == 0xF0 ? 3
                                           : 4;
    if (extra > 3 || bytes.size() - i <= extra) return false;
    for (size_t k = 1; k <= extra; ++k)
      if ((static_cast<unsigned char>(bytes[i + k]) & 0xC0) != 0x80) return false;
    i += extra + 1;
  }
  return true;
}

bool isControl(unsigned codePoint) {
  return codePoint < 0x20 || (codePoint >= 0x7F && codePoint <= 0x9F);
}

void appendEscaped(std::string& text, unsigned codePoint) {
  char escaped[5];
  std::snprintf(escaped, sizeof escaped, "\\x%02X", codePoint);
  text += escaped;
}

}  // namespace

std::string printableText(std::string_view bytes) {
  bool utf8 = isUtf8(bytes);
  std::string text;
  text.reserve(bytes.size());
  for (size_t i = 0; i < bytes.size(); ++i) {
    auto c = static_cast<unsigned char>(bytes[i]);
    if (utf8 && c == 0xC2 && i + 1 < bytes.size()) {
      // U+0080..U+00BF: C1 controls among them.
      auto next = static_cast<unsigned char>(bytes[i + 1]);
      if (isControl(next)) {
        appendEscaped(text, next);
        ++i;
        continue;
      }
    }
    if (isControl(c) && (c < 0x80 || !utf8)) {
      appendEscaped(text, c);
    } else if (c < 0x80 || utf8) {
      text += static_cast<char>(c);
    } else {
      text += static_cast<char>(0xC0 | (c >> 6));
      text += static_cast<char>(0x80 | (c & 0x3F));
    }
  }
  return text;
}

}  // namespace wircam
