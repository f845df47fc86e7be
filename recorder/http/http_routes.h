// Which of wirc-recorder's web resources a request path names, decided
// apart from the server so that it can be tested and fuzzed on its own.
#pragma once

#include <string>
#include <string_view>

namespace wircam::recorder {

struct Route {
  enum class Kind {
    Page,
    Login,  // GET /login: the sign-in page, served without the token
    Status,
    Events,
    Live,
    RecordingList,
    Recording,
    Cameras,              // GET /api/cameras
    Snapshot,             // GET /api/cameras/NAME/snapshot.jpg
    RecordingIndex,       // GET /api/recordings
    RecordingEntry,       // /api/recordings/FILE (DELETE only)
    CameraCommand,        // POST /api/cameras/NAME/{follow,target,request-control}
    Drive,                // GET /api/cameras/NAME/drive: the drive mode's WebSocket
    Whep,                 // POST /api/cameras/NAME/whep: a WebRTC viewer's offer (WHEP)
    WhepSession,          // DELETE /api/cameras/NAME/whep/SESSION: its end
    Playback,             // GET /play/FILE.mjpg?from=SECONDS: a recording replayed as MJPEG
    Export,               // GET /api/export?camera=&start=&end=&format=: a range as one file
    ConfigReload,         // POST /api/config/reload: the config file read again
    Metrics,              // GET /metrics: Prometheus's text format
    Fleet,                // GET /api/fleet: every recorder of the fleet (--fleet)
    FleetRecordings,      // GET /api/fleet/recordings?vehicle=&camera=&day=: theirs, merged
    FleetVehicleCommand,  // POST /api/fleet/vehicles/SERIAL/{follow,target,drive}
    ApiNotFound,          // any other /api/ path: 404 with JSON
    NotFound
  };
  Kind kind = Kind::NotFound;
  // The camera (Live, Snapshot, CameraCommand, Drive), the file, or the
  // vehicle's serial (FleetVehicleCommand).
  std::string name;
  // CameraCommand: follow, target or request-control; FleetVehicleCommand:
  // follow, target or drive; WhepSession: its id.
  std::string action;
};

// `path` as libsoup hands it over (percent-decoded).
Route routeOf(std::string_view path);

// The methods a resource of this kind serves, as a 405's Allow header says
// them; nullptr for a path that names nothing (a 404 whatever the method).
const char* allowedMethods(Route::Kind kind);

// Whether `allowed` (as allowedMethods gives it) holds `method`.
bool methodAllowed(const char* allowed, std::string_view method);

// Whether a request carries the access token, as "Authorization: Bearer T",
// as the password of "Authorization: Basic" (any user name), or the
// "wircam_token" cookie (either header may be null). Compared in constant
// time.
bool carriesToken(const char* authorization, const char* cookie, std::string_view token);

// A recording may be served by this name: a plain file name (no folder, not
// hidden) of a video or sidecar. Whether it is a regular file in the folder
// and not a link is the server's check on the disk.
bool isRecordingName(std::string_view name);

// The media type a recording is served with, or nullptr for other files.
const char* recordingContentType(std::string_view name);

}  // namespace wircam::recorder
