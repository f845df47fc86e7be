// wirc-recorder-servers.so (live/live_servers.h), loaded on first use from
// its place beside the recorder's executable (the same relative place in
// the build tree and under an install prefix) and kept for the process's
// life: its table of servers, or why it cannot be loaded.
#pragma once

#include <string>

#include "common/expected.h"
#include "live/live_servers.h"

namespace wircam::recorder {

Expected<const LiveServers*, std::string> liveServers();

// The process's end with `code`, once nothing is left to finish (no
// destructor of the caller's runs). While a thread of the loaded module is
// still at work (LiveServers::busyAtExit: a DTLS key being made, seconds on
// a loaded machine), at once, stdio flushed (std::_Exit): a stop does not
// wait for a key nobody will use, and exit's handlers do not take libcrypto
// down under that thread. Otherwise std::exit, its handlers and all (a
// sanitizer's leak check among them).
[[noreturn]] void endProcess(int code);

}  // namespace wircam::recorder
