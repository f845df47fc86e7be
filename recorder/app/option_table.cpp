// The rows of optionTable() and deviceKeyTable(): each option once, with
// what it reads and refuses.
#include "app/option_table.h"

#include <glib.h>

#include <cmath>
#include <memory>

#include "app/option_values.h"
#include "fleet/mqtt_url.h"
#include "record/retention.h"
#include "wirc/channel_list.h"

namespace wircam::recorder {

namespace {

using Apply = std::function<OptionProblem(RecorderOptions&, const char*)>;

// Readers for the common kinds of value, each checking its range and saying
// it the same way.
Apply seconds(double RecorderOptions::*field, double low, double high) {
  return [=](RecorderOptions& o, const char* value) -> OptionProblem {
    auto s = number(value);
    if (!s || *s < low || *s > high) {
      char range[64];
      g_snprintf(range, sizeof range, "seconds, %g..%g", low, high);
      return range;
    }
    o.*field = *s;
    return std::nullopt;
  };
}

Apply wholeNumber(unsigned RecorderOptions::*field, double low, double high, const char* unit) {
  return [=](RecorderOptions& o, const char* value) -> OptionProblem {
    auto n = number(value);
    if (!n || *n < low || *n > high || *n != std::floor(*n)) {
      char range[64];
      g_snprintf(range, sizeof range, "%s%s%g..%g", unit, *unit ? ", " : "", low, high);
      return range;
    }
    o.*field = static_cast<unsigned>(*n);
    return std::nullopt;
  };
}

Apply onOff(bool RecorderOptions::*field) {
  return [=](RecorderOptions& o, const char* value) -> OptionProblem {
    std::string on = value;
    if (on != "on" && on != "off") return "on or off";
    o.*field = on == "on";
    return std::nullopt;
  };
}

Apply text(std::string RecorderOptions::*field) {
  return [=](RecorderOptions& o, const char* value) -> OptionProblem {
    o.*field = value;
    return std::nullopt;
  };
}

Apply optionalText(std::optional<std::string> RecorderOptions::*field) {
  return [=](RecorderOptions& o, const char* value) -> OptionProblem {
    o.*field = value;
    return std::nullopt;
  };
}

Apply serverAddress(std::optional<ServerAddress> RecorderOptions::*field) {
  return [=](RecorderOptions& o, const char* value) -> OptionProblem {
    auto address = parseServerAddress(value);
    if (!address) return "[HOST]:PORT, as in :8080 or 127.0.0.1:8080";
    o.*field = *address;
    return std::nullopt;
  };
}

Apply size(uint64_t RecorderOptions::*field) {
  return [=](RecorderOptions& o, const char* value) -> OptionProblem {
    auto bytes = byteSize(value);
    if (!bytes) return "a size like 500M or 20G";
    o.*field = *bytes;
    return std::nullopt;
  };
}

Apply duration(std::chrono::seconds RecorderOptions::*field) {
  return [=](RecorderOptions& o, const char* value) -> OptionProblem {
    auto d = parseDuration(value);
    if (!d || d->count() == 0) return "a duration like 7d, 12h, 30m or 90s";
    o.*field = *d;
    return std::nullopt;
  };
}

Apply channels(std::optional<std::string> RecorderOptions::*field, bool periods) {
  return [=](RecorderOptions& o, const char* value) -> OptionProblem {
    auto list = wirc::parseChannelList(value);
    if (!list) return list.error();
    auto invalid = periods ? wirc::validate(wirc::Ccfg{*list}) : wirc::validate(wirc::Fcfg{*list});
    if (invalid) return invalid->message();
    o.*field = value;
    return std::nullopt;
  };
}

// A topic prefix: no wildcards, no empty level at either end.
OptionProblem topicPrefix(const std::string& prefix, const char* example) {
  if (prefix.empty() || prefix.find_first_of("+# ") != std::string::npos || prefix.front() == '/' ||
      prefix.back() == '/')
    return std::string("a topic prefix without + # or a leading or trailing /, like ") + example;
  return std::nullopt;
}

OptionProblem commandLine(RecorderOptions& o, const char* value) {
  gchar** argv = nullptr;
  GError* error = nullptr;
  if (!g_shell_parse_argv(value, nullptr, &argv, &error)) {
    std::string problem = error->message;
    g_error_free(error);
    return "cannot split the command: " + problem;
  }
  o.onSegmentClosed.assign(argv, argv + g_strv_length(argv));
  g_strfreev(argv);
  return std::nullopt;
}

// A flag's value in the config file (the command line's flag says true).
std::optional<bool> trueOrFalse(const char* value) {
  std::string v = value;
  if (v == "true" || v == "1") return true;
  if (v == "false" || v == "0") return false;
  return std::nullopt;
}

constexpr const char* kDevices = "Devices and cameras";
constexpr const char* kFiles = "Files";
constexpr const char* kRetention = "Retention";
constexpr const char* kDetection = "Detection and following";
constexpr const char* kWeb = "Web server";
constexpr const char* kFoxglove = "Foxglove";
constexpr const char* kFleet = "MQTT and hooks";
constexpr const char* kOther = "Other";

std::vector<OptionSpec> makeTable() {
  return {
      {.name = "device",
       .value = "HOST[:PORT][,control=URI]",
       .fallback = "discovery",
       .section = kDevices,
       .help = "a vehicle to record, port 1984 unless given; repeatable. Without any `--device` "
               "(and no config file) the device is found by discovery. `control=rcoip://H:P`, "
               "`btemp://H:P` or `wirc://H:P`: with `--follow`, steer that vehicle instead of the "
               "WiRC device whose camera is recorded ([cousins.md](cousins.md))",
       .apply = [](RecorderOptions& o, const char* value) -> OptionProblem {
         auto target = deviceTarget(value);
         if (!target) return target.error();
         o.devices.push_back(*target);
         return std::nullopt;
       },
       .example = "192.168.1.1:1985",
       .commandLineOnly = true},
      {.name = "config",
       .value = "FILE",
       .fallback = "",
       .section = kDevices,
       .help = "read options and devices from an INI file ([below](#the-config-file)); a reload "
               "(`SIGHUP`, `POST /api/config/reload`) reads it again",
       .commandLineOnly = true},
      {.name = "camera",
       .value = "N",
       .fallback = "0",
       .section = kDevices,
       .reloadable = true,
       .deviceKey = "cameras",
       .help = "a camera of each device to record, 0..255; repeatable",
       .apply = [](RecorderOptions& o, const char* value) -> OptionProblem {
         auto camera = number(value);
         if (!camera || *camera < 0 || *camera > 255 || *camera != std::floor(*camera))
           return "0..255";
         o.cameras.push_back(static_cast<int>(*camera));
         return std::nullopt;
       },
       .example = "1"},
      {.name = "periods",
       .value = "US,...",
       .fallback = "20000",
       .section = kDevices,
       .reloadable = true,
       .help = "servo periods the login sets (CCFG): 12 comma-separated µs values or one for "
               "all, 5000..20000, ch1/ch2, ch3/ch4 and ch5/ch6 equal",
       .apply = channels(&RecorderOptions::periods, true),
       .example = "10000"},
      {.name = "failsafe",
       .value = "US,...",
       .fallback = "1500",
       .section = kDevices,
       .reloadable = true,
       .help = "what each channel does when the link is lost (FCFG): 800..2200 µs, 0 = hold the "
               "last pulse, 65535 = no pulse",
       .apply = channels(&RecorderOptions::failsafe, false),
       .example = "1000"},

      {.name = "out",
       .value = "DIR",
       .fallback = "",
       .section = kFiles,
       .help = "where the files go (created if missing)",
       .apply = text(&RecorderOptions::outDir),
       .example = "elsewhere"},
      {.name = "segment",
       .value = "S",
       .fallback = "60",
       .section = kFiles,
       .reloadable = true,
       .help = "seconds per segment, at least 1",
       .apply = [](RecorderOptions& o, const char* value) -> OptionProblem {
         auto s = number(value);
         if (!s || *s < 1) return "seconds >= 1";
         o.segmentSeconds = *s;
         return std::nullopt;
       },
       .example = "30"},
      {.name = "segment-size",
       .value = "SIZE",
       .fallback = "none",
       .section = kFiles,
       .reloadable = true,
       .help = "also end a segment at SIZE bytes (at least `100K`; `K`, `M`, `G`, `T` are powers "
               "of 1000)",
       .apply = [](RecorderOptions& o, const char* value) -> OptionProblem {
         auto bytes = byteSize(value);
         if (!bytes || *bytes < 100000) return "a size of at least 100K, like 100M";
         o.segmentBytes = *bytes;
         return std::nullopt;
       },
       .example = "100M"},
      {.name = "format",
       .value = "mkv|mp4",
       .fallback = "mkv",
       .section = kFiles,
       .reloadable = true,
       .help = "container; `mp4` needs `--codec h264` (mp4mux cannot carry JPEG)",
       .apply = [](RecorderOptions& o, const char* value) -> OptionProblem {
         std::string format = value;
         if (format != "mkv" && format != "mp4") return "mkv or mp4";
         o.container = format == "mp4" ? Container::kMp4 : Container::kMatroska;
         return std::nullopt;
       },
       .example = "mp4",
       .needs = {"codec", "h264"}},
      {.name = "codec",
       .value = "jpeg|h264",
       .fallback = "jpeg",
       .section = kFiles,
       .help = "`jpeg`: the camera's frames as they arrive, untouched; `h264`: transcoded with "
               "`x264enc` (Main profile, veryfast, zero latency, a key frame every 0.5 s; needs "
               "gstreamer1.0-plugins-ugly); the live servers' feeds depend on it, so a change "
               "takes a restart",
       .apply = [](RecorderOptions& o, const char* value) -> OptionProblem {
         std::string codec = value;
         if (codec != "jpeg" && codec != "h264") return "jpeg or h264";
         o.codec = codec == "h264" ? Codec::kH264 : Codec::kJpeg;
         return std::nullopt;
       },
       .example = "h264"},
      {.name = "bitrate",
       .value = "KBPS",
       .fallback = "2000",
       .section = kFiles,
       .reloadable = true,
       .help = "H.264 bit rate, 50..100000",
       .apply = wholeNumber(&RecorderOptions::h264Kbps, 50, 100000, "kbit/s"),
       .example = "1500"},
      {.name = "telemetry-track",
       .value = "on|off",
       .fallback = "on",
       .section = kFiles,
       .reloadable = true,
       .help = "the telemetry also as the file's text track `telemetry`; `off` keeps it in the "
               "sidecar only, which spares a thread per camera (for many cameras on a small "
               "machine)",
       .apply = onOff(&RecorderOptions::telemetryTrack),
       .example = "off"},
      {.name = "record-queue",
       .value = "SIZE",
       .fallback = "8M",
       .section = kFiles,
       .reloadable = true,
       .help = "how much of a camera's video may wait for a slow disk (`100K`..`1G`); past "
               "it the newest frames are dropped from the file, counted in `/api/status` "
               "(`recording_dropped`), `/metrics` and the log, while the live view, detection "
               "and following go on. `0`: no queue, a thread less per camera, but a disk that "
               "stalls then stalls the camera's source and branches too",
       .apply = [](RecorderOptions& o, const char* value) -> OptionProblem {
         auto bytes = byteSize(value);
         if (!bytes || (*bytes != 0 && (*bytes < 100'000 || *bytes > 1'000'000'000)))
           return "0, or a size of 100K..1G, like 8M";
         o.recordQueueBytes = *bytes;
         return std::nullopt;
       },
       .example = "16M"},
      {.name = "duration",
       .value = "S",
       .fallback = "none",
       .section = kFiles,
       .help = "stop after S seconds",
       .apply = [](RecorderOptions& o, const char* value) -> OptionProblem {
         auto s = number(value);
         if (!s || *s <= 0) return "seconds > 0";
         o.duration = *s;
         return std::nullopt;
       },
       .example = "90"},
      {.name = "status",
       .value = "S",
       .fallback = "1",
       .section = kFiles,
       .help = "seconds between status lines",
       .apply = [](RecorderOptions& o, const char* value) -> OptionProblem {
         auto s = number(value);
         if (!s || *s <= 0) return "seconds > 0";
         o.statusSeconds = *s;
         return std::nullopt;
       },
       .example = "5"},
      {.name = "stall-timeout",
       .value = "S",
       .fallback = "5",
       .section = kFiles,
       .reloadable = true,
       .help = "a camera logged in but without a frame for S seconds (0.5..3600) is `no-video`: "
               "its file is closed and its pipeline started again, with backoff",
       .apply = seconds(&RecorderOptions::stallSeconds, 0.5, 3600),
       .example = "2.5"},

      {.name = "max-bytes",
       .value = "SIZE",
       .fallback = "none",
       .section = kRetention,
       .reloadable = true,
       .help = "keep the recordings under SIZE (e.g. `500M`, `20G`) by deleting the oldest "
               "finished segments",
       .apply = size(&RecorderOptions::maxBytes),
       .example = "20G"},
      {.name = "min-free",
       .value = "SIZE",
       .fallback = "none",
       .section = kRetention,
       .reloadable = true,
       .help = "delete the oldest finished segments while the disk has less than SIZE free",
       .apply = size(&RecorderOptions::minFree),
       .example = "1G"},
      {.name = "max-age",
       .value = "DURATION",
       .fallback = "none",
       .section = kRetention,
       .reloadable = true,
       .help = "delete finished segments older than DURATION (`7d`, `12h`, `30m`, `90s`; by "
               "their last write), looked at on start-up, at every closed segment and every "
               "minute",
       .apply = duration(&RecorderOptions::maxAge),
       .example = "7d"},
      {.name = "keep-events",
       .value = "DURATION",
       .fallback = "none",
       .section = kRetention,
       .reloadable = true,
       .help = "keep the segments whose sidecar shows a tag seen or a command off neutral this "
               "long instead of `--max-age` (longer)",
       .apply = duration(&RecorderOptions::keepEvents),
       .example = "30d",
       .needs = {"max-age", "7d"}},

      {.name = "detect",
       .value = "FAMILY",
       .fallback = "none",
       .section = kDetection,
       .reloadable = true,
       .help = "find AprilTags of this family (e.g. `tag36h11`; a misspelt one is refused with "
               "the list); detections go to the telemetry",
       .apply = text(&RecorderOptions::detectFamily),
       .example = "tag25h9"},
      {.name = "follow",
       .value = nullptr,
       .fallback = "off",
       .section = kDetection,
       .reloadable = true,
       .deviceKey = "follow",
       .help = "steer the vehicle after the largest tag (needs `--detect`)",
       .apply = [](RecorderOptions& o, const char* value) -> OptionProblem {
         auto on = trueOrFalse(value);
         if (!on) return "true or false";
         o.follow = *on;
         return std::nullopt;
       },
       .example = "true",
       .needs = {"detect", "tag36h11"}},
      {.name = "follow-tuning",
       .value = "K=V[,K=V...]",
       .fallback = "wirccontrol's",
       .section = kDetection,
       .reloadable = true,
       .help = "the follower's gains and limits: `steering-kp`, `steering-ki`, `steering-kd`, "
               "`throttle-kp`, `throttle-ki`, `throttle-kd` (0..100), `target-distance` "
               "(0.05..100 m), `max-throttle` (0..1); see [replay.md](replay.md)",
       .apply = [](RecorderOptions& o, const char* value) -> OptionProblem {
         auto tuning = followTuning(value);
         if (!tuning) return tuning.error();
         o.followTuning = *tuning;
         return std::nullopt;
       },
       .example = "steering-kp=2,max-throttle=0.5",
       .needs = {"detect", "tag36h11", "follow", "true"}},
      {.name = "marvelmind",
       .value = "HOST[:PORT]",
       .fallback = "none",
       .section = kDetection,
       .reloadable = true,
       .deviceKey = "marvelmind",
       .help = "a Marvelmind dashboard (port 49200) to ask where the vehicle is; needs "
               "`--beacon` ([marvelmind.md](marvelmind.md))",
       .apply = optionalText(&RecorderOptions::marvelmind),
       .example = "192.168.1.50:49201",
       .needs = {"beacon", "5"}},
      {.name = "beacon",
       .value = "ADDR[,ADDR]",
       .fallback = "none",
       .section = kDetection,
       .reloadable = true,
       .deviceKey = "beacon",
       .help = "the vehicle's mobile beacon address(es), 1..254: its positions go to the "
               "telemetry, `/api/status` and the live view's map",
       .apply = optionalText(&RecorderOptions::beacons),
       .example = "5,6",
       .needs = {"marvelmind", "192.168.1.50"}},

      {.name = "http",
       .value = "[HOST]:PORT",
       .fallback = "off",
       .section = kWeb,
       .help = "the web page and HTTP API ([web-interface.md](web-interface.md)); without HOST "
               "on 127.0.0.1 only; `:0` picks a free port (logged as `live view at http://…`). "
               "Another HOST (e.g. `0.0.0.0`) needs `--http-token`",
       .apply = serverAddress(&RecorderOptions::http),
       .example = ":8081"},
      {.name = "http-token",
       .value = "T",
       .fallback = "none",
       .section = kWeb,
       .help = "every request needs the token (Bearer, Basic with T as the password, or the "
               "sign-in cookie); 16 characters at least, no spaces, quotes, commas or "
               "semicolons (e.g. `openssl rand -hex 16`). RTSP and the Foxglove WebSocket ask "
               "for it too. Control, driving, deleting and reloading are refused without it",
       .apply = [](RecorderOptions& o, const char* value) -> OptionProblem {
         std::string token = value;
         if (token.size() < 16 || token.find_first_of(" ;,\"\\") != std::string::npos)
           return "at least 16 characters, no spaces, quotes, commas or semicolons (e.g. from "
                  "openssl rand -hex 16)";
         o.httpToken = token;
         return std::nullopt;
       },
       .example = "0123456789abcdef0123"},
      {.name = "http-cert",
       .value = "FILE",
       .fallback = "none",
       .section = kWeb,
       .help = "serve HTTPS with this PEM certificate (and `wss://` with `--foxglove`); with "
               "`--http-key`",
       .apply = text(&RecorderOptions::httpCert),
       .example = "cert.pem",
       .needs = {"http-key", "key.pem", "http", ":8081"}},
      {.name = "http-key",
       .value = "FILE",
       .fallback = "none",
       .section = kWeb,
       .help = "the certificate's PEM key",
       .apply = text(&RecorderOptions::httpKey),
       .example = "key.pem",
       .needs = {"http-cert", "cert.pem", "http", ":8081"}},
      {.name = "http-idle-timeout",
       .value = "S",
       .fallback = "10",
       .section = kWeb,
       .help = "close a connection with no request in progress (silent, idle, or still sending "
               "its headers) for S seconds (0.1..3600)",
       .apply = seconds(&RecorderOptions::httpIdleSeconds, 0.1, 3600),
       .example = "30"},
      {.name = "webrtc",
       .value = "on|off",
       .fallback = "on",
       .section = kWeb,
       .help = "the page's live view over WebRTC, WHEP at `/api/cameras/NAME/whep` "
               "([webrtc.md](webrtc.md))",
       .apply = onOff(&RecorderOptions::webrtc),
       .example = "off"},
      {.name = "webrtc-stun",
       .value = "stun://HOST:PORT",
       .fallback = "none",
       .section = kWeb,
       .help = "a STUN server for viewers across NAT (none is contacted unless set)",
       .apply = [](RecorderOptions& o, const char* value) -> OptionProblem {
         if (!g_str_has_prefix(value, "stun://") ||
             !g_uri_is_valid(value, G_URI_FLAGS_NONE, nullptr))
           return "a STUN server as stun://HOST:PORT";
         o.webrtcStun = value;
         return std::nullopt;
       },
       .example = "stun://192.168.1.2:3478"},
      {.name = "webrtc-turn",
       .value = "turn://USER:PASSWORD@HOST:PORT",
       .fallback = "none",
       .section = kWeb,
       .help = "a TURN server (`turns://` for TLS)",
       .apply = [](RecorderOptions& o, const char* value) -> OptionProblem {
         if ((!g_str_has_prefix(value, "turn://") && !g_str_has_prefix(value, "turns://")) ||
             !g_uri_is_valid(value, G_URI_FLAGS_HAS_PASSWORD, nullptr))
           return "a TURN server as turn://USER:PASSWORD@HOST:PORT (or turns://)";
         o.webrtcTurn = value;
         return std::nullopt;
       },
       .example = "turn://me:secret@192.168.1.2:3478"},
      {.name = "webrtc-kbps",
       .value = "N",
       .fallback = "600",
       .section = kWeb,
       .help = "each camera's VP8 bitrate for WebRTC, 50..20000",
       .apply = wholeNumber(&RecorderOptions::webrtcKbps, 50, 20000, "kbit/s"),
       .example = "800"},
      {.name = "rtsp",
       .value = "[HOST]:PORT",
       .fallback = "off",
       .section = kWeb,
       .help = "RTSP server: `rtsp://HOST:PORT/<device>/cam<N>` ([rtsp.md](rtsp.md)); without "
               "HOST on 127.0.0.1 only",
       .apply = serverAddress(&RecorderOptions::rtsp),
       .example = ":8554"},

      {.name = "foxglove",
       .value = "[HOST]:PORT",
       .fallback = "off",
       .section = kFoxglove,
       .help = "a Foxglove WebSocket (`foxglove.websocket.v1`) for Foxglove and Lichtblick: each "
               "camera's image, tags, telemetry, log and pose, and `/STREAM/drive` from their "
               "Teleop panel ([foxglove.md](foxglove.md)); logged as `Foxglove WebSocket at "
               "ws://…`. Without HOST on 127.0.0.1 only; another HOST needs `--http-token`. "
               "Token and TLS (`wss://`) as for `--http`",
       .apply = serverAddress(&RecorderOptions::foxglove),
       .example = ":8765"},
      {.name = "foxglove-max-clients",
       .value = "N",
       .fallback = "8",
       .section = kFoxglove,
       .help = "Foxglove clients at once, 1..64; the next is told why and closed",
       .apply = wholeNumber(&RecorderOptions::foxgloveMaxClients, 1, 64, ""),
       .example = "4"},

      {.name = "mqtt",
       .value = "mqtt://[USER:PASS@]HOST[:PORT]",
       .fallback = "off",
       .section = kFleet,
       .help = "publish status, detections and events and take commands ([mqtt.md](mqtt.md)); "
               "`mqtts://` for TLS (port 8883)",
       .apply = [](RecorderOptions& o, const char* value) -> OptionProblem {
         auto url = parseMqttUrl(value);
         if (!url) return url.error();
         o.mqtt = value;
         return std::nullopt;
       },
       .example = "mqtt://192.168.1.3"},
      {.name = "mqtt-cafile",
       .value = "FILE",
       .fallback = "system CAs",
       .section = kFleet,
       .help = "the CA (PEM) that signed the broker's certificate",
       .apply = text(&RecorderOptions::mqttCaFile),
       .example = "ca.pem",
       .needs = {"mqtt", "mqtts://192.168.1.3"}},
      {.name = "mqtt-prefix",
       .value = "P",
       .fallback = "wircam",
       .section = kFleet,
       .help = "topic prefix (no `+`, `#`, leading or trailing `/`)",
       .apply = [](RecorderOptions& o, const char* value) -> OptionProblem {
         if (auto problem = topicPrefix(value, "wircam or lab/rovers")) return problem;
         o.mqttPrefix = value;
         return std::nullopt;
       },
       .example = "lab/rovers"},
      {.name = "mqtt-discovery",
       .value = "[PREFIX]",
       .fallback = "off",
       .section = kFleet,
       .help = "Home Assistant MQTT discovery under PREFIX (`homeassistant`); "
               "`--mqtt-discovery=PREFIX` works too; in the config file `true` or a prefix",
       .apply = [](RecorderOptions& o, const char* value) -> OptionProblem {
         // Alone (or =true in the config file): Home Assistant's own prefix.
         std::string prefix = value;
         if (prefix == "true") prefix = "homeassistant";
         if (prefix == "false") return std::nullopt;
         if (auto problem = topicPrefix(prefix, "homeassistant")) return problem;
         o.mqttDiscovery = prefix;
         return std::nullopt;
       },
       .example = "ha",
       .needs = {"mqtt", "mqtt://192.168.1.3"},
       .optionalValue = true},
      {.name = "mqtt-snapshot-interval",
       .value = "S",
       .fallback = "10",
       .section = kFleet,
       .help = "with discovery: each camera's newest JPEG every S seconds (0.5..3600)",
       .apply = seconds(&RecorderOptions::mqttSnapshotSeconds, 0.5, 3600),
       .example = "20"},
      {.name = "mqtt-detections-rate",
       .value = "HZ",
       .fallback = "0",
       .section = kFleet,
       .help = "at most HZ detection messages a second per stream (0: every frame with tags)",
       .apply = [](RecorderOptions& o, const char* value) -> OptionProblem {
         auto rate = number(value);
         if (!rate || *rate < 0 || *rate > 1000)
           return "messages per second, 0..1000 (0: every frame)";
         o.mqttDetectionsRate = *rate;
         return std::nullopt;
       },
       .example = "2"},
      {.name = "on-segment-closed",
       .value = "CMD",
       .fallback = "none",
       .section = kFleet,
       .help = "run CMD (split as a shell would, never through one) with the segment's path and "
               "its sidecar's as two more arguments, for each segment as it closes; failures are "
               "retried with backoff ([below](#segment-hooks))",
       .apply = commandLine,
       .example = "upload --fast"},
      {.name = "hook-timeout",
       .value = "S",
       .fallback = "600",
       .section = kFleet,
       .help = "a hook running longer is stopped (its whole process group) and retried "
               "(1..86400)",
       .apply = seconds(&RecorderOptions::hookTimeoutSeconds, 1, 86400),
       .example = "60"},
      {.name = "hook-drain",
       .value = "S",
       .fallback = "15",
       .section = kFleet,
       .help = "at exit, how long the hooks still queued get (0..3600)",
       .apply = seconds(&RecorderOptions::hookDrainSeconds, 0, 3600),
       .example = "5"},

      {.name = "help",
       .value = nullptr,
       .fallback = "",
       .section = kOther,
       .help = "the option list, config keys, file names, MQTT topics and exit codes",
       .commandLineOnly = true},
  };
}

Expected<int, std::string> cameraNumber(const std::string& text) {
  auto camera = number(text.c_str());
  if (!camera || *camera < 0 || *camera > 255 || *camera != std::floor(*camera))
    return unexpected(std::string("cameras 0..255, as in 0;1"));
  return static_cast<int>(*camera);
}

std::vector<DeviceKeySpec> makeDeviceKeys() {
  return {
      {.key = "host",
       .value = "HOST",
       .help = "its address (needed)",
       .apply = [](DeviceTarget& d, const std::string& value) -> OptionProblem {
         d.host = value;
         return std::nullopt;
       }},
      {.key = "port",
       .value = "PORT",
       .help = "its port (1984)",
       .apply = [](DeviceTarget& d, const std::string& value) -> OptionProblem {
         auto port = number(value.c_str());
         if (!port || *port < 1 || *port > 65535 || *port != std::floor(*port))
           return "a port is 1..65535";
         d.port = static_cast<uint16_t>(*port);
         return std::nullopt;
       }},
      {.key = "cameras",
       .value = "N;N...",
       .help = "its cameras, instead of `--camera`'s",
       .apply = [](DeviceTarget& d, const std::string& value) -> OptionProblem {
         d.cameras.clear();
         std::unique_ptr<gchar*, decltype(&g_strfreev)> items(
             g_strsplit_set(value.c_str(), ";,", -1), g_strfreev);
         for (gchar** item = items.get(); *item; ++item) {
           if (!**item) continue;  // "0;1;"
           auto camera = cameraNumber(*item);
           if (!camera) return camera.error();
           d.cameras.push_back(*camera);
         }
         if (d.cameras.empty()) return "a list like 0;1";
         return std::nullopt;
       }},
      {.key = "follow",
       .value = "true|false",
       .help = "whether it follows, instead of `--follow`",
       .apply = [](DeviceTarget& d, const std::string& value) -> OptionProblem {
         auto on = trueOrFalse(value.c_str());
         if (!on) return "true or false";
         d.follow = *on;
         return std::nullopt;
       }},
      {.key = "control",
       .value = "URI",
       .help = "steer `rcoip://H:P`, `btemp://H:P` or `wirc://H:P` instead of this device, as "
               "`--device`'s `control=`",
       .apply = [](DeviceTarget& d, const std::string& value) -> OptionProblem {
         auto control = parseControlTarget(value);
         if (!control) return control.error();
         d.control = *control;
         return std::nullopt;
       }},
      {.key = "marvelmind",
       .value = "HOST[:PORT]",
       .help = "its Marvelmind dashboard, instead of `--marvelmind`",
       .apply = [](DeviceTarget& d, const std::string& value) -> OptionProblem {
         d.marvelmind = value;
         return std::nullopt;
       }},
      {.key = "beacon",
       .value = "ADDR[,ADDR]",
       .help = "its beacon(s), instead of `--beacon`",
       .apply = [](DeviceTarget& d, const std::string& value) -> OptionProblem {
         d.beacons = value;
         return std::nullopt;
       }},
  };
}

}  // namespace

const std::vector<OptionSpec>& optionTable() {
  static const std::vector<OptionSpec> table = makeTable();
  return table;
}

const OptionSpec* findOption(const std::string& name) {
  for (const auto& spec : optionTable())
    if (name == spec.name) return &spec;
  return nullptr;
}

const std::vector<DeviceKeySpec>& deviceKeyTable() {
  static const std::vector<DeviceKeySpec> table = makeDeviceKeys();
  return table;
}

const std::vector<const char*>& optionSections() {
  static const std::vector<const char*> sections = {kDevices, kFiles,    kRetention, kDetection,
                                                    kWeb,     kFoxglove, kFleet,     kOther};
  return sections;
}

}  // namespace wircam::recorder
