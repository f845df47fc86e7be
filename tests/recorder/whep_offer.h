// A WHEP offer as a browser would make it (VP8, receive only), with the
// given candidate lines.
#pragma once

#include <string>

namespace wircam::testing {

inline std::string offerWith(const std::string& candidates) {
  return "v=0\r\no=- 42 2 IN IP4 127.0.0.1\r\ns=-\r\nt=0 0\r\na=group:BUNDLE 0\r\n"
         "m=video 9 UDP/TLS/RTP/SAVPF 96\r\nc=IN IP4 0.0.0.0\r\n" +
         candidates +
         "a=ice-ufrag:BMgz\r\na=ice-pwd:+VxwY9p7YVQQRFGi1gqpXvIm\r\n"
         "a=fingerprint:sha-256 C3:57:54:E5:C4:01:93:0F:D1:A5:D5:FE:ED:6A:F8:9B:85:7F:45:8E:6E:"
         "81:AA:D2:9A:42:F0:63:3F:AF:41:02\r\na=setup:actpass\r\na=mid:0\r\na=recvonly\r\n"
         "a=rtcp-mux\r\na=rtpmap:96 VP8/90000\r\n";
}

}  // namespace wircam::testing
