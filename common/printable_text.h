// The one way a string a peer sent (a device or transmitter name, an MQTT
// payload or topic, an HTTP path) becomes safe to put in a log line or on a
// terminal: nothing in it can start a new line, move the cursor or set a
// colour, and a zero byte cannot cut it short.
#pragma once

#include <string>
#include <string_view>

namespace wircam {

// UTF-8 stays as it is when the whole text is UTF-8; otherwise each byte is
// read as Latin-1. Control characters, C0 (below 0x20), DEL and C1
// (U+0080..U+009F, whose CSI 0x9B a terminal obeys like ESC [), come out as
// \xNN, naming the character.
std::string printableText(std::string_view bytes);

}  // namespace wircam
