// gst-rtsp-server's authentication for the recorder's access token, as the
// web server takes it: Basic credentials with the token as the password
// (any user name, e.g. rtsp://viewer:TOKEN@host:8554/...), or a Bearer
// header. Without it a request gets 401 with WWW-Authenticate: Basic.
// (GstRTSPAuth's own Basic support matches whole user:password pairs, so
// "any user name" needs its authenticate step replaced.)
#pragma once

#include <gst/rtsp-server/rtsp-server.h>

#include <string>

namespace wircam::recorder {

// The role the token grants; a factory gives it access and construction.
inline constexpr const char* kRtspViewerRole = "viewer";

// A new authentication object (transfer full) for `token`.
GstRTSPAuth* rtspTokenAuth(const std::string& token);

}  // namespace wircam::recorder
