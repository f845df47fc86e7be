// The ICE servers a WebRTC viewer may use, and where it gathers.
#pragma once

#include <string>
#include <vector>

namespace wircam::recorder {

struct IceServers {
  std::string stun;  // "stun://HOST:PORT"; empty: none (nothing is contacted)
  std::string turn;  // "turn://USER:PASSWORD@HOST:PORT"; empty: none
  // The local addresses ICE gathers on (the web server's own: loopback by
  // default); empty: every interface.
  std::vector<std::string> localAddresses;
};

}  // namespace wircam::recorder
