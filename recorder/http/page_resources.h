// The web page's files (http/page/), compiled into the binary as a GLib
// resource. The page at "/" is live_view.html with its style and scripts in
// place: one response, nothing fetched from elsewhere.
//   live_view.html  the page; STYLE, PLAYER_SCRIPT, CONTROL_SCRIPT and
//                   PAGE_SCRIPT mark where the files below go
//   live_view.css   its style
//   live_view.js    the cameras, their overlays from /api/events, the
//                   status, the map, the recordings; INITIAL_STATE marks
//                   where the server puts the cameras, their last
//                   detections and the trails, so the first picture
//                   already carries its overlay
//   player.js       the player of a recording, with its telemetry timeline
//   control.js      follow, target, control right, drive mode
//   login.html      /login, with --http-token
#pragma once

#include <string>

namespace wircam::recorder {

// A file of the page by name ("login.html").
std::string pageFile(const char* name);
// The page at "/", with `initialState` (JSON) in place.
std::string liveViewPage(const std::string& initialState);

}  // namespace wircam::recorder
