// The Foxglove server's state per camera and per client, shared by its
// files: foxglove_server.cpp (connections, sessions, channels) and
// foxglove_publish.cpp (what goes out to the clients).
#pragma once

#include <libsoup/soup.h>

#include <atomic>
#include <map>
#include <optional>
#include <set>
#include <string>

#include "foxglove/annex_b.h"
#include "http/foxglove_server.h"
#include "http/foxglove_session.h"
#include "live/live_servers.h"

namespace wircam::recorder {

struct FoxgloveServer::Feed {
  FoxgloveCamera camera;
  bool h264 = false;  // its images are the recording's H.264
  int listener = 0;
  std::map<FoxgloveTopic, uint32_t> channels;
  std::atomic<int> imageSubscribers{0};  // read on the streaming thread
  std::map<uint64_t, int64_t> stamps;    // the recent frames' times (ns), by PTS
  // H.264 to Annex B, from the caps it was read from (main loop).
  GstCaps* annexBCaps = nullptr;
  std::optional<AnnexB> annexB;
  ~Feed() { gst_clear_caps(&annexBCaps); }
};

struct FoxgloveServer::Client {
  FoxgloveServer* server;
  SoupWebsocketConnection* connection;
  GSocket* socket;  // its TCP socket (a reference; under TLS too), for the send queue
  std::string peer;
  FoxgloveSession session;
  gulong messageHandler = 0, closedHandler = 0;
  std::map<uint32_t, bool> decoding;  // H.264 channel -> it has had a key frame since a gap
  uint64_t dropped = 0;
  std::set<std::string> disobeyed;  // cameras whose vehicle did not obey it, told so
};

}  // namespace wircam::recorder
