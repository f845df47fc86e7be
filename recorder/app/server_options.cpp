// The option table's rows for the servers and fleets: web, Foxglove, MQTT
// and the segment hook.
#include <glib.h>

#include "app/option_rows.h"
#include "app/option_values.h"
#include "fleet/mqtt_url.h"

namespace wircam::recorder::option_rows {

std::vector<OptionSpec> serverOptionRows() {
  return {
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
      {.name = "fleet",
       .value = nullptr,
       .fallback = "off",
       .section = kFleet,
       .help = "the page and `GET /api/fleet` show every recorder announced on the broker, with "
               "its cameras and their vehicles; `GET /api/fleet/recordings` asks them all "
               "([fleet.md](fleet.md))",
       .apply = [](RecorderOptions& o, const char* value) -> OptionProblem {
         auto on = trueOrFalse(value);
         if (!on) return "true or false";
         o.fleet = *on;
         return std::nullopt;
       },
       .example = "true",
       .needs = {"mqtt", "mqtt://192.168.1.3", "http", ":8080"}},
      {.name = "fleet-url",
       .value = "URL",
       .fallback = "the listening address",
       .section = kFleet,
       .help = "the HTTP address other recorders and browsers reach this one at, where the "
               "listening one is not (NAT, a proxy): announced to the fleet; its host stands for "
               "RTSP's and Foxglove's too (with `--mqtt` and `--http`)",
       .apply = [](RecorderOptions& o, const char* value) -> OptionProblem {
         std::string url = value;
         if (!(url.starts_with("http://") || url.starts_with("https://")) || url.size() < 9)
           return "an http:// or https:// URL, as in http://rover-lab.example:8080/";
         o.fleetUrl = url;
         return std::nullopt;
       },
       .example = "http://recorder-a.lab:8080/",
       .needs = {"mqtt", "mqtt://192.168.1.3", "http", ":8080"}},
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

}  // namespace wircam::recorder::option_rows
