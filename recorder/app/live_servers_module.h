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

}  // namespace wircam::recorder
