// wirc-recorder's log: each event a line on stderr, on a terminal after a
// newline so that it never runs into the status line (a file or the journal
// gets the lines alone). Text a peer sent (MQTT topics and
// payloads, device names, link events) is put through printableText()
// before it becomes part of `line`, so no peer can start a line of its own.
#pragma once

#include <unistd.h>

#include <cstdio>
#include <string>

#include "common/printable_text.h"

namespace wircam::recorder {

inline void logLine(const std::string& line) {
  static const bool terminal = isatty(STDERR_FILENO);
  std::fprintf(stderr, "%swirc-recorder: %s\n", terminal ? "\n" : "", line.c_str());
}

}  // namespace wircam::recorder
