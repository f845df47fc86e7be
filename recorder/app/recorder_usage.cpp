// wirc-recorder --help: every option, the config file and the exit codes.
#include "app/option_table.h"
#include "app/recorder_options.h"

namespace wircam::recorder {

namespace {

std::string deviceKeys() {
  std::string keys;
  for (const auto& key : deviceKeyTable())
    keys += (keys.empty() ? "" : ", ") + std::string(key.key);
  return keys;
}

}  // namespace

std::string usage() {
  return R"(Usage: wirc-recorder --device HOST[:PORT] [--device ...] --out DIR [OPTIONS]

Records the cameras of one or more WiRC devices into segmented files, the
JPEG frames muxed as they arrive (no re-encoding) or transcoded to H.264,
with the telemetry in a JSON-lines sidecar per segment and as a text track in
the file. A device that is off is waited for. SIGINT or SIGTERM finishes every
file and exits 0.

)" + optionsHelp() +
         R"(Config file (GKeyFile/INI): a [recorder] group with the long options above
as keys (all but device, config and help), and one [device NAME] group per
vehicle with the keys )" +
         deviceKeys() + R"(
(cameras=0;1, follow=true, control=rcoip://H:P or btemp://H:P):

  [recorder]
  out=recordings
  detect=tag36h11
  [device rover]
  host=192.168.1.1
  cameras=0;1
  follow=true
  marvelmind=192.168.1.50:49200
  beacon=5

Reload: SIGHUP (or POST /api/config/reload with --http) reads the config
file again. Cameras added start, cameras removed finish their file and stop,
cameras whose settings changed restart alone; the others record on. A file
that does not validate, or that changes an option marked "restart" in
docs/recorder.md (the servers, --out, --codec, --status, --duration, the
MQTT and hook options), is refused and nothing changes.

Files: DIR/<device>-cam<N>-YYYYMMDDTHHMMSSZ.mkv (or .mp4), named by the UTC
time of their first frame, each starting at 0 on a key frame; a segment also
ends where the device was lost. Beside each, <same name>.jsonl with one JSON
object per event: {"pts": ns on the segment's timeline, "utc": "...Z", "type":
"stats"|"detections"|"control"|"session"|"vehicle"|"position"|"position-stale",
...}; the same objects are the file's text track "telemetry" (unless
--telemetry-track off). DIR/index.json lists the finished segments (camera,
file, start_utc, duration_s, frames, bytes); wirc-export makes one file of a
time range of them.

MQTT topics (PREFIX/STREAM, STREAM as in the file names):
  PREFIX/available          online/offline, retained; offline is the last will
  PREFIX/STREAM/status      retained JSON: state, fps, loss, battery_v,
                            has_control, following, target, position; on
                            change and at least every 5 s
  PREFIX/STREAM/detections  JSON per frame with tags (and one when they go)
  PREFIX/STREAM/events      session events, {"type":"segment-closed",...},
                            hook failures
  PREFIX/STREAM/snapshot    with --mqtt-discovery: the newest JPEG, retained
  PREFIX/STREAM/follow/set  ON or OFF (takes effect at once; OFF = neutral)
  PREFIX/STREAM/target/set  a tag id (-1: the largest)
  PREFIX/STREAM/drive/set   {"steering": -1..1, "throttle": -1..1}, held for
                            the 250 ms dead-man: send one every 100 ms
  wircam-fleet/recorders/ID this recorder's announcement, retained (fleet.md)
  wircam-fleet/vehicles/SERIAL/follow/set, .../target/set, .../drive/set
                            the same commands for a vehicle by its serial,
                            obeyed by the recorder that holds it

Exit status: 0 finished cleanly (or stopped by a signal before any frame),
1 error (or --duration ended with nothing recorded), 2 bad arguments, 3 the
disk filled (the open segments were finished first).
)";
}

}  // namespace wircam::recorder
