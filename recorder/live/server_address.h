// Where a server listens: "[HOST]:PORT"; no host means this machine only
// (127.0.0.1; 0.0.0.0 for every interface), port 0 one the system picks
// (the recorder prints it). The recorder's options read it from the
// command line and the config file.
#pragma once

#include <cstdint>
#include <string>

namespace wircam::recorder {

struct ServerAddress {
  std::string host;
  uint16_t port = 0;
  std::string listenHost() const { return host.empty() ? "127.0.0.1" : host; }
  bool operator==(const ServerAddress&) const = default;
};

}  // namespace wircam::recorder
