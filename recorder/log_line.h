// wirc-recorder's log: each event a line on stderr, after a newline so that
// it never runs into the status line. Text a peer sent (MQTT topics and
// payloads, device names, link events) is put through printableText()
// before it becomes part of `line`, so no peer can start a line of its own.
#pragma once

#include <cstdio>
#include <string>

#include "common/printable_text.h"

namespace wircam::recorder {

inline void logLine(const std::string& line) {
  std::fprintf(stderr, "\nwirc-recorder: %s\n", line.c_str());
}

}  // namespace wircam::recorder
