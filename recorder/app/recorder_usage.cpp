// wirc-recorder --help: every option, the config file and the exit codes.
#include "app/recorder_options.h"

namespace wircam::recorder {

const char* usage() {
  return R"(Usage: wirc-recorder --device HOST[:PORT] [--device ...] --out DIR [OPTIONS]

Records the cameras of one or more WiRC devices into segmented files, the
JPEG frames muxed as they arrive (no re-encoding) or transcoded to H.264,
with the telemetry in a JSON-lines sidecar per segment and as a text track in
the file. A device that is off is waited for. SIGINT or SIGTERM finishes every
file and exits 0.

  --device HOST[:PORT][,control=URI]
                         a device to record (default port 1984); repeatable.
                         Without --device the device is found by discovery.
                         control=rcoip://H:P or btemp://H:P: with --follow,
                         steer that RCOIP receiver or BTEMP robot instead of
                         the WiRC device (whose camera is still recorded)
  --config FILE          read devices and options from an INI file (below)
  --camera N             camera to record (default 0); repeatable
  --out DIR              where the files go (created if missing)
  --segment S            seconds per segment (default 60)
  --segment-size SIZE    also end a segment at SIZE (e.g. 100M)
  --format mkv|mp4       container (default mkv); mp4 needs --codec h264
  --codec jpeg|h264      jpeg: the camera's frames as they are (default);
                         h264: transcoded with x264enc (gstreamer1.0-plugins-ugly),
                         Main profile (WebRTC viewers get these frames as they are)
  --bitrate KBPS         H.264 bit rate (default 2000)
  --telemetry-track on|off
                         the telemetry as the file's text track too (default
                         on); off: in the sidecar only, which spares a thread
                         per camera and the muxer waiting on the text at every
                         frame (for many cameras on a small machine)
  --detect FAMILY        find AprilTags (e.g. tag36h11); detections go to telemetry
  --follow               steer the vehicle after the largest tag (needs --detect)
  --follow-tuning K=V[,K=V...]
                         the follower's gains and limits (wirccontrol's
                         properties): steering-kp, -ki, -kd, throttle-kp, -ki,
                         -kd, target-distance, max-throttle; e.g. tried on a
                         replayed drive (wirc-sim --replay)
  --marvelmind HOST[:PORT]
                         a Marvelmind dashboard (port default 49200) to ask
                         where the vehicle is; with --beacon
  --beacon ADDR[,ADDR]   the vehicle's mobile beacon address(es), 1..254:
                         its positions go to telemetry ("position", metres),
                         /api/status and the live view's map
  --periods US,...       channel periods the login sets (CCFG): 12 values or
                         one for all, 5000..20000 µs (default 20000)
  --failsafe US,...      what each channel does when the link is lost (FCFG):
                         800..2200 µs, 0 = hold, 65535 = no pulse (default 1500).
                         Every login sends both; the device takes them from the
                         first transmitter logged in (so they overwrite what
                         wirc-cli configure set) and refuses them to later ones
  --duration S           stop after S seconds
  --status S             seconds between status updates (default 1)
  --stall-timeout S      a camera logged in but without a frame for S seconds
                         is "no-video": its file is closed and its pipeline
                         started again, with backoff (default 5)
  --max-bytes SIZE       keep the recordings under SIZE (e.g. 500M, 20G) by
                         deleting the oldest finished segments
  --min-free SIZE        delete the oldest finished segments while the disk
                         has less than SIZE free
  --max-age DURATION     delete finished segments older than DURATION (e.g. 7d,
                         12h, 30m; their last write counts), looked at every
                         minute
  --keep-events DURATION keep the segments whose telemetry shows tags seen or
                         commands sent this long instead of --max-age (longer)
  --http [HOST]:PORT     web server: live view, playback, control and drive
                         mode at /, status at /api/status, cameras at
                         /api/cameras, recordings at /api/recordings, a time
                         range as one file at /api/export, Prometheus's
                         metrics at /metrics (e.g. --http :8080). Without HOST it listens on 127.0.0.1
                         only; another HOST (e.g. 0.0.0.0) needs --http-token
  --http-token T         every request needs "Authorization: Bearer T", Basic
                         credentials with T as the password (any user name:
                         http://viewer:T@host/...) or the cookie the page's
                         /login sets (16 characters at least); RTSP asks for it
                         too; control, driving and deleting need it always
  --http-cert FILE --http-key FILE
                         serve HTTPS with this certificate and key (PEM): the
                         page, API, streams and drive WebSocket over TLS (the
                         token then never travels in clear)
  --http-idle-timeout S  close an HTTP connection with no request in progress (silent,
                         idle, or still sending its headers) for S seconds (default 10)
  --webrtc on|off        the page's live view over WebRTC (VP8, about 1/3 of
                         MJPEG's bitrate) with MJPEG as its fallback, and drive
                         mode over a WebRTC data channel; WHEP at
                         /api/cameras/NAME/whep (default on)
  --webrtc-stun stun://HOST:PORT
  --webrtc-turn turn://USER:PASSWORD@HOST:PORT
                         ICE servers for viewers across networks (NAT); none
                         by default, and none is ever contacted unless set
  --webrtc-kbps N        each camera's VP8 bitrate for WebRTC (default 600)
  --mqtt mqtt://[USER:PASS@]HOST[:PORT]
                         publish status, detections and events to an MQTT
                         broker and take follow/target commands (below);
                         mqtts:// for TLS (port 8883 by default)
  --mqtt-cafile FILE     mqtts://: the CA (PEM) that signed the broker's
                         certificate (default: the system's CAs)
  --mqtt-prefix P        topic prefix (default wircam)
  --mqtt-discovery [PREFIX]
                         Home Assistant MQTT discovery (prefix default
                         homeassistant): each camera a device with a camera
                         (snapshots), a following switch, a target number,
                         battery/fps/loss sensors and a connectivity sensor
  --mqtt-snapshot-interval S
                         the camera entity's snapshot every S seconds
                         (default 10)
  --mqtt-detections-rate HZ
                         at most HZ detection messages per second and stream
                         (default 0: every frame with tags)
  --on-segment-closed CMD
                         run CMD (split like a shell would, never through
                         one) with the segment's path and its sidecar's as
                         two more arguments, for each segment as it closes;
                         failures are retried with backoff (e.g. a script
                         that runs rclone: docs/recorder.md, "Segment hooks")
  --hook-timeout S       a hook running longer is stopped and retried (default 600)
  --hook-drain S         at exit, how long the hooks still queued get (default 15)
  --rtsp [HOST]:PORT     RTSP server: rtsp://HOST:PORT/<device>/cam<N>; without
                         HOST on 127.0.0.1 only
  --foxglove [HOST]:PORT Foxglove WebSocket for Foxglove and Lichtblick: each
                         camera's image, tags, telemetry, log and pose, and
                         /STREAM/drive from their Teleop panel; without HOST
                         on 127.0.0.1 only; token and TLS as for --http
  --foxglove-max-clients N
                         Foxglove clients at once (default 8, at most 64)
  -h, --help             this text

Config file (GKeyFile/INI): a [recorder] group with the long options as keys
(out, segment, segment-size, format, codec, bitrate, telemetry-track, detect,
follow, follow-tuning, max-bytes, min-free, max-age, keep-events, status,
stall-timeout, http, http-token, http-cert, http-key, http-idle-timeout, webrtc,
webrtc-stun, webrtc-turn, webrtc-kbps, rtsp, foxglove, foxglove-max-clients,
periods, failsafe, marvelmind, beacon, mqtt, mqtt-cafile, mqtt-prefix,
mqtt-discovery, mqtt-snapshot-interval, mqtt-detections-rate,
on-segment-closed, hook-timeout, hook-drain), and one [device NAME] group per
vehicle with host, port, cameras (e.g. 0;1), follow, control (rcoip://H:P or
btemp://H:P, as on the command line), marvelmind and beacon:

  [recorder]
  out=recordings
  detect=tag36h11
  [device rover]
  host=192.168.1.1
  cameras=0;1
  follow=true
  marvelmind=192.168.1.50:49200
  beacon=5

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

Exit status: 0 finished cleanly (or stopped by a signal before any frame),
1 error (or --duration ended with nothing recorded), 2 bad arguments, 3 the
disk filled (the open segments were finished first).
)";
}

}  // namespace wircam::recorder
